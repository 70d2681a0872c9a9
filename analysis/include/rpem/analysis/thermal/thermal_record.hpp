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
  bool coolant = false;         ///< the log has T_coolant (else thermal.coolant_C is used)
  bool averaged = false;
  std::string read_as;      ///< what the log was read as, for the tools (io::describe; the format for phase samples)
  io::SampleCounts counts;  ///< what the estimator run did with the samples (its regimes)
};

/// Runs the configured estimator over the log — read as `source` says, as `rpem estimate` reads it: our drive or
/// averaged log, VESC Tool's realtime log, a user's column map; each cell held to the machine's limits — and its
/// observer with the thermal configuration's observer settings. Throws io::DriveLogError / io::ConfigError on bad
/// input.
[[nodiscard]] ThermalRecord record_thermal(const io::LogSource& source, const io::MachineConfig& machine,
                                           const io::ThermalConfig& thermal);

}  // namespace rpem::analysis
