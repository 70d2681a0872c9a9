#pragma once
// What crosses rpemd's thread boundaries, each through an SpscQueue with one producer and one consumer
// (docs/rpemd.md, "Threads"): plain copyable data, no strings, no heap.
//   source  → loop:       SourceSample (a phase or an averaged sample, source_sample.hpp)
//   source  → publisher:  SourceReport (source.hpp)
//   control → loop:       Command (supervisory commands and reloads, in the order they were accepted)
//   control → publisher:  ControlReport
//   loop    → publisher:  Report (an estimate, a measurement, or the loop's statistics)

#include <cstdint>
#include <variant>

#include "rpem/core/drive_sample.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"

namespace rpem::daemon {

enum class DaemonState : std::int8_t { kStarting = 0, kRunning = 1, kStale = 2, kStopping = 3 };

/// The verdict on an RPEM_COMMAND message (diagnostics_t.last_command_result; numbers never change).
enum class CommandResult : std::int8_t {
  kNone = 0,
  kApplied = 1,  ///< accepted: the loop applies it at the start of its next period
  kRejectedDisabled = 2,
  kRejectedOldSequence = 3,
  kRejectedBadValues = 4,
  kRejectedUnknown = 5,
  kRejectedBusy = 6,  ///< the loop's command queue was full; the same sequence number may be sent again
  kRejectedUnauthenticated = 7,  ///< unsigned (key id 0) while authentication is required
  kRejectedUnknownKey = 8,       ///< a key id rpemd does not hold
  kRejectedBadMac = 9,           ///< a known key id, a wrong MAC: forged or altered
  kRejectedNotPersisted = 10,    ///< the sequence number could not be persisted (replay protection)
};
inline constexpr int kCommandResults = 11;

struct Command {
  enum class Kind : std::uint8_t { kReset, kFreeze, kUnfreeze, kSetValues, kReconfigure };
  Kind kind = Kind::kReset;
  std::int64_t seq = 0;  ///< RPEM_COMMAND sequence number; 0 for a reload (SIGHUP)
  double psi_m_Wb = 0.0;  ///< kSetValues
  double r_s_Ohm = 0.0;
  LiveConfig live;        ///< kReconfigure: the whole reloaded configuration, as one object
};

struct EstimateReport {
  std::int64_t utime_us = 0;
  std::int64_t sample_time_us = 0;
  std::int64_t newest_rx_ns = 0;  ///< kernel receive time of the newest sample (CAN), 0 otherwise
  std::int64_t samples = 0;
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0, psi_m_pu = 0.0, r_s_pu = 0.0;
  double t_magnet_C = 0.0, t_winding_C = 0.0, speed_pu = 0.0;
  bool psi_m_valid = false, r_s_valid = false, psi_m_converged = false, r_s_converged = false;
  bool psi_m_adapting = false, r_s_adapting = false, frozen = false;
  double psi_m_age_s = -1.0, r_s_age_s = -1.0;  ///< since the last adaptation; −1: never adapted
  DaemonState state = DaemonState::kStarting;
  core::Algorithm algorithm = core::Algorithm::kSga;
  // The last values that were valid, converged and adapting (persisted by the publisher), and how long
  // ago they adapted.
  bool has_good_psi_m = false, has_good_r_s = false;
  double good_psi_m_Wb = 0.0, good_r_s_Ohm = 0.0;
  double good_psi_m_age_s = 0.0, good_r_s_age_s = 0.0;
};

struct MeasurementReport {
  std::int64_t utime_us = 0;
  std::int64_t sample_time_us = 0;
  double theta_el_rad = 0.0, omega_el_rad_s = 0.0, u_dc_V = 0.0;
  double i_d_A = 0.0, i_q_A = 0.0, i_hat_d_A = 0.0, i_hat_q_A = 0.0, eps_d_A = 0.0, eps_q_A = 0.0;
  double t_winding_sensor_C = 0.0, t_drive_sensor_C = 0.0;  ///< the drive's own sensors; NaN: not reported
};

/// The loop's counters (totals) and statistics (the last reporting interval), as diagnostics rows.
struct LoopStatsReport {
  std::int64_t utime_us = 0;
  DaemonState state = DaemonState::kStarting;
  std::int32_t input_queue_depth = 0;
  DiagnosticsRows rows;
};

using Report = std::variant<EstimateReport, MeasurementReport, LoopStatsReport>;

/// The control thread's counters, and what it alone knows: whether commands are enabled now and the
/// verdict on the newest command.
struct ControlReport {
  DiagnosticsRows rows;
  bool commands_enabled = false;
  std::int64_t last_command_seq = 0;
  CommandResult last_command_result = CommandResult::kNone;
};

}  // namespace rpem::daemon
