#pragma once
// What crosses rpemd's thread boundaries, each through an SpscQueue with one producer and one consumer
// (docs/rpemd.md, "Threads"): plain copyable data, no strings, no heap. An LCM message's fields travel as
// its mirror, generated from its .lcm file (rpem/mirror/<struct>.hpp): the .lcm file is their one definition.
//   source  → loop:       SourceSample (a phase or an averaged sample, source_sample.hpp)
//   source  → publisher:  SourceReport (source.hpp)
//   control → loop:       Command (supervisory commands and reloads, in the order they were accepted)
//   control → publisher:  ControlReport
//   loop    → publisher:  Report (an estimate, a measurement, or the loop's statistics)

#include <cstdint>
#include <variant>

#include "rpem/core/drive_sample.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/core/thermal_resume.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"
#include "rpem/mirror/estimate_t.hpp"
#include "rpem/mirror/measurement_t.hpp"

namespace rpem::daemon {

enum class DaemonState : std::int8_t {
  kStarting = mirror::estimate_t::STATE_STARTING,
  kRunning = mirror::estimate_t::STATE_RUNNING,
  kStale = mirror::estimate_t::STATE_STALE,
  kStopping = mirror::estimate_t::STATE_STOPPING,
};
/// estimate_t.state and diagnostics_t.state carry a DaemonState's number.
[[nodiscard]] constexpr bool operator==(std::int8_t state, DaemonState s) noexcept {
  return state == static_cast<std::int8_t>(s);
}

/// The verdict on an RPEM_COMMAND message (diagnostics_t.last_command_result; numbers never change).
enum class CommandResult : std::int8_t {
  kNone = 0,
  kApplied = 1,  ///< accepted: the loop applies it at the start of its next period
  kRejectedDisabled = 2,
  kRejectedOldSequence = 3,
  kRejectedBadValues = 4,
  kRejectedUnknown = 5,
  kRejectedBusy = 6,             ///< the loop's command queue was full; the same sequence number may be sent again
  kRejectedUnauthenticated = 7,  ///< unsigned (key id 0) while authentication is required
  kRejectedUnknownKey = 8,       ///< a key id rpemd does not hold
  kRejectedBadMac = 9,           ///< a known key id, a wrong MAC: forged or altered
  kRejectedNotPersisted = 10,    ///< the sequence number could not be persisted (replay protection)
};
inline constexpr int kCommandResults = 11;

struct Command {
  enum class Kind : std::uint8_t { kReset, kFreeze, kUnfreeze, kSetValues, kReconfigure };
  Kind kind = Kind::kReset;
  std::int64_t seq = 0;   ///< RPEM_COMMAND sequence number; 0 for a reload (SIGHUP)
  double psi_m_Wb = 0.0;  ///< kSetValues
  double r_s_Ohm = 0.0;
  LiveConfig live;  ///< kReconfigure: the whole reloaded configuration, as one object
};

/// RPEM_ESTIMATE's fields (the mirror of lcm_types/rpem_estimate_t.lcm; the publisher copies them all), and
/// what the publisher needs besides.
struct EstimateReport : mirror::estimate_t {
  std::int64_t newest_rx_ns = 0;                      ///< kernel receive time of the newest sample (CAN), 0 otherwise
  core::Algorithm algorithm = core::Algorithm::kSga;  ///< estimate_t.algorithm, which the publisher spells
  // The last values that were valid, converged and adapting (persisted by the publisher), and how long
  // ago they adapted.
  bool has_good_psi_m = false, has_good_r_s = false;
  double good_psi_m_Wb = 0.0, good_r_s_Ohm = 0.0;
  double good_psi_m_age_s = 0.0, good_r_s_age_s = 0.0;
  core::ThermalSnapshot thermal;  ///< the fusion's state (persisted: a restart resumes it); nodes 0: none
  /// The fusion started soaked although a winding sensor is configured: it gave no reading in the first step to test
  /// the start (core::ThermalEstimate::start_assumed_soaked; without a sensor rpemd says so at its start).
  bool thermal_start_untested_by_sensor = false;
};

/// RPEM_MEASUREMENT's fields (the mirror of lcm_types/rpem_measurement_t.lcm).
using MeasurementReport = mirror::measurement_t;

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
