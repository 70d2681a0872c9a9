#pragma once
// Subcommands of the `rpem` tool. Each registers its options on the app and runs when selected.

#include <CLI/CLI.hpp>
#include <functional>

#include "rpem/io/exit_codes.hpp"

namespace rpem::tools {

/// Exit codes: rpem/io/exit_codes.hpp (shared with rpemd).
using io::kExitConfig;
using io::kExitDataError;
using io::kExitIoError;
using io::kExitOk;
using io::kExitUsage;

using Runner = std::function<int()>;

Runner add_estimate_command(CLI::App& app);
Runner add_sim_command(CLI::App& app);
Runner add_reproduce_command(CLI::App& app);
Runner add_figures_command(CLI::App& app);
Runner add_replay_command(CLI::App& app);
Runner add_record_command(CLI::App& app);
Runner add_listen_command(CLI::App& app);
Runner add_command_command(CLI::App& app);
Runner add_publish_estimate_command(CLI::App& app);
Runner add_keygen_command(CLI::App& app);
Runner add_diagnose_command(CLI::App& app);
Runner add_thermal_command(CLI::App& app);

}  // namespace rpem::tools
