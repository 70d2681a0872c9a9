#pragma once
// Persistence of the last converged estimates (docs/rpemd.md): JSON, written atomically — a temporary
// file in the same directory, fsync, rename, fsync of the directory — so a crash leaves the old or the
// new file, never a torn one. Not real-time: the publisher thread writes, start-up reads.

#include <cstdint>
#include <optional>
#include <string>

#include "rpem/core/thermal_resume.hpp"

namespace rpem::daemon {

/// The thermal fusion's node temperatures, covariance and load, and when they were the fusion's (docs/thermal.md,
/// "A restart"): a restart on a hot machine starts there, not at the coolant.
struct PersistedThermal {
  core::ThermalSnapshot state;  ///< nodes 0: none
  std::int64_t at_unix_s = 0;
};

struct PersistedEstimates {
  std::optional<double> psi_m_Wb;  ///< present if ψm had converged
  std::optional<double> r_s_Ohm;   ///< present if r_s had converged
  std::int64_t written_unix_s = 0;
  /// When each value last adapted (docs/rpemd.md, "Validity and age"); a file without them (older
  /// rpemd): when it was written.
  std::int64_t psi_m_adapted_unix_s = 0;
  std::int64_t r_s_adapted_unix_s = 0;
  PersistedThermal thermal;
};

/// Writes atomically; returns an empty string or the reason it failed.
[[nodiscard]] std::string write_state_file(const std::string& path, const PersistedEstimates& e);

/// The last accepted RPEM_COMMAND sequence number (replay protection across restarts), in its own file
/// beside the state file — `commands.json` in the same directory — because the control thread owns it
/// and writes it, durably, before a command is queued; the publisher owns the estimates' file.
[[nodiscard]] std::string command_sequence_file(const std::string& state_file);
/// Writes atomically; returns an empty string or the reason it failed.
[[nodiscard]] std::string write_command_sequence(const std::string& path, std::int64_t last_accepted_seq);
/// 0 if there is no file; throws std::runtime_error (naming the file) if it is unreadable — replay
/// protection never silently restarts from 0.
[[nodiscard]] std::int64_t load_command_sequence(const std::string& path);

enum class StateFileStatus : std::int8_t { kNone = 0, kLoaded = 1, kTooOld = 2, kImplausible = 3, kCorrupt = 4 };

struct LoadedState {
  StateFileStatus status = StateFileStatus::kNone;
  PersistedEstimates estimates;
  std::string message;  ///< for the log
};

/// Reads and checks a state file: age against max_age_s (and not in the future), values against the
/// bounds of D_M, a thermal state's against physics (above absolute zero, a covariance's symmetry and
/// variances) and its own age (older than max_age_s: left out, said in the message). A missing file is
/// kNone; anything unreadable is kCorrupt (reported, not fatal).
[[nodiscard]] LoadedState load_state_file(const std::string& path, double max_age_s, double psi_min_Wb, double psi_max_Wb,
                                          double rs_min_Ohm, double rs_max_Ohm);

}  // namespace rpem::daemon
