#pragma once
// What crosses rpemd's thread boundaries, through SpscQueue: plain copyable data, no strings, no heap.
//   source thread → loop:     core::DriveSample
//   publisher/main → loop:    Command
//   loop → publisher:         Report (an estimate, a measurement, or the loop's statistics)

#include <cstdint>
#include <variant>

#include "rpem/core/drive_sample.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/daemon/daemon_config.hpp"

namespace rpem::daemon {

enum class DaemonState : std::int8_t { kStarting = 0, kRunning = 1, kStale = 2, kStopping = 3 };

/// Results reported for a command (diagnostics_t.last_command_result).
enum class CommandResult : std::int8_t {
  kNone = 0,
  kApplied = 1,
  kRejectedDisabled = 2,
  kRejectedOldSequence = 3,
  kRejectedBadValues = 4,
  kRejectedUnknown = 5,
};

struct Command {
  enum class Kind : std::uint8_t { kReset, kFreeze, kUnfreeze, kSetValues, kReconfigure };
  Kind kind = Kind::kReset;
  std::int64_t seq = 0;  ///< RPEM_COMMAND sequence number; 0 for internal commands (SIGHUP)
  double psi_m_Wb = 0.0;
  double r_s_Ohm = 0.0;
  core::MachineSi machine;           ///< kReconfigure
  core::EstimatorSettings settings;  ///< kReconfigure
  TemperatureModel temperature;      ///< kReconfigure
  ValidityConfig validity;           ///< kReconfigure
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
  DaemonState state = DaemonState::kStarting;
  core::Algorithm algorithm = core::Algorithm::kSga;
  // The last values that were valid and converged (persisted by the publisher).
  bool has_good_psi_m = false, has_good_r_s = false;
  double good_psi_m_Wb = 0.0, good_r_s_Ohm = 0.0;
};

struct MeasurementReport {
  std::int64_t utime_us = 0;
  std::int64_t sample_time_us = 0;
  double theta_el_rad = 0.0, omega_el_rad_s = 0.0, u_dc_V = 0.0;
  double i_d_A = 0.0, i_q_A = 0.0, i_hat_d_A = 0.0, i_hat_q_A = 0.0, eps_d_A = 0.0, eps_q_A = 0.0;
};

struct LoopStatsReport {
  std::int64_t utime_us = 0;
  DaemonState state = DaemonState::kStarting;
  std::int64_t period_ns = 0;
  double latency_min_us = 0.0, latency_mean_us = 0.0, latency_max_us = 0.0, latency_p99_us = 0.0;
  double work_max_us = 0.0;
  std::int64_t overruns = 0, periods = 0;
  std::int64_t samples = 0, resyncs = 0, rejected_non_finite = 0, predictor_resets = 0, projections = 0;
  double eps_rms_d_A = 0.0, eps_rms_q_A = 0.0, gain_norm = 0.0;
  double hessian_sga_psi_m = 0.0, hessian_sga_r_s = 0.0, hessian_gna_det = 0.0;
  std::int32_t input_queue_depth = 0;
  std::int64_t output_queue_drops = 0;
  std::int64_t commands_applied = 0;
  std::int64_t last_command_seq = 0;
  CommandResult last_command_result = CommandResult::kNone;
  std::int64_t config_reloads = 0;
};

using Report = std::variant<EstimateReport, MeasurementReport, LoopStatsReport>;

}  // namespace rpem::daemon
