#pragma once
// Subcommands of the `rpem` tool. Each registers its options on the app and runs when selected.

#include <CLI/CLI.hpp>
#include <functional>

namespace rpem::tools {

/// Exit codes (sysexits.h): shared by every subcommand and by rpemd.
inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 64;      ///< EX_USAGE: bad command line
inline constexpr int kExitDataError = 65;  ///< EX_DATAERR: malformed drive log or input data
inline constexpr int kExitIoError = 74;    ///< EX_IOERR: cannot read or write a file
inline constexpr int kExitConfig = 78;     ///< EX_CONFIG: bad configuration

using Runner = std::function<int()>;

Runner add_estimate_command(CLI::App& app);
Runner add_sim_command(CLI::App& app);
Runner add_reproduce_command(CLI::App& app);
Runner add_figures_command(CLI::App& app);
Runner add_replay_command(CLI::App& app);
Runner add_record_command(CLI::App& app);
Runner add_listen_command(CLI::App& app);
Runner add_command_command(CLI::App& app);
Runner add_diagnose_command(CLI::App& app);

}  // namespace rpem::tools
