#pragma once
// Exit codes of every program (rpem and its subcommands, rpemd), from sysexits.h: written once here.
// rpemd.service's RestartPreventExitStatus= names kExitConfig's number (78), so that a configuration
// error is not restarted in a loop.

#include <sysexits.h>
#include <csignal>

namespace rpem::io {

inline constexpr int kExitOk = EX_OK;
inline constexpr int kExitUsage = EX_USAGE;        ///< 64: bad command line
inline constexpr int kExitDataError = EX_DATAERR;  ///< 65: malformed drive log or input data
inline constexpr int kExitSoftware = EX_SOFTWARE;  ///< 70: rpemd's required real-time set-up failed
inline constexpr int kExitIoError = EX_IOERR;      ///< 74: cannot read or write a file, or reach LCM
inline constexpr int kExitConfig = EX_CONFIG;      ///< 78: bad configuration
/// 130: stopped by Ctrl-C (SIGINT) or SIGTERM before it finished, nothing written (the shells' 128 + SIGINT)
inline constexpr int kExitInterrupted = 128 + SIGINT;

}  // namespace rpem::io
