#pragma once
// A drive log as the thermal network sees it (docs/thermal.md): the estimator run over the log as rpemd
// would run it, and per step of the thermal filter the load, the estimator's observations of ψm and R_s
// (core::ThermalObserver) and the log's winding sensor and coolant — never a magnet sensor.

#include <string>
#include <vector>

#include "rpem/core/thermal_observer.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/sample_counts.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::analysis {

struct ThermalRecord {
  std::string log;
  std::vector<core::ThermalStepData> steps;
  std::vector<double> t_s;      ///< each step's end [s]
  bool winding_sensor = false;  ///< the log has T_winding
  bool coolant = false;         ///< the log has T_coolant with a reading in it (else thermal.coolant_C is used)
  bool averaged = false;
  std::string read_as;      ///< what the log was read as, for the tools (io::describe; the format for phase samples)
  io::SampleCounts counts;  ///< what the estimator run did with the samples (its regimes)
  /// The first step of each logging session, ascending, the first 0 (docs/thermal.md, "A folder of logs"): one log is
  /// one session. Each session starts from its own state — the network, the filter and the sensor's lag restart at
  /// its first step (core::start_temperatures_C) — and its steps' t_s follow the session before's end.
  std::vector<std::size_t> session_first_step{0};
  std::vector<std::string> session_logs;  ///< each session's log, in that order
  std::vector<bool> session_coolant;      ///< whether each session's log has T_coolant, in that order

  /// Whether session j's log has T_coolant (a record built without session_coolant: the record's own flag).
  [[nodiscard]] bool session_has_coolant(std::size_t j) const {
    return j < session_coolant.size() ? session_coolant[j] : coolant;
  }

  /// Whether step k is the first of a session.
  [[nodiscard]] bool starts_session(std::size_t k) const;
  /// One past session j's last step.
  [[nodiscard]] std::size_t session_end(std::size_t j) const {
    return j + 1 < session_first_step.size() ? session_first_step[j + 1] : steps.size();
  }
};

/// Runs the configured estimator over the log — read as `source` says, as `rpem estimate` reads it: our drive or
/// averaged log, VESC Tool's realtime log, a user's column map; each cell held to the machine's limits — and its
/// observer with the thermal configuration's observer settings. Throws io::DriveLogError / io::ConfigError on bad
/// input.
[[nodiscard]] ThermalRecord record_thermal(const io::LogSource& source, const io::MachineConfig& machine,
                                           const io::ThermalConfig& thermal);

/// The sessions of one machine (a folder of logs, each recorded on its own: record_thermal) as one record named
/// `name`: their steps one after another, each session's t_s shifted to begin one step after the one before ends.
/// It has a winding sensor where any session has one, the coolant where every session has it; its `counts` are
/// empty (each session's are its own, for the tools to say as it is recorded). Throws
/// std::invalid_argument on no session, or on a session without steps.
[[nodiscard]] ThermalRecord join_sessions(std::vector<ThermalRecord> sessions, const std::string& name);

}  // namespace rpem::analysis
