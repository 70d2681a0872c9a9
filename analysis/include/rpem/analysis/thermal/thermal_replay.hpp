#pragma once
// The thermal network over a recorded log (thermal_record.hpp), two ways: open loop from the soaked start
// (the model alone), and the fusion filter as rpemd runs it (core::ThermalFusion::apply on each recorded step).
// Both start afresh at each session's first step (ThermalRecord::session_first_step).

#include <functional>
#include <vector>

#include "rpem/analysis/thermal/thermal_record.hpp"
#include "rpem/core/thermal_fusion.hpp"

namespace rpem::analysis {

/// The network's temperatures at the end of each step, open loop from each session's start: core::start_temperatures_C
/// at its first step (every node at the coolant, the winding at its sensor; every node there where the sensor says the
/// machine is not soaked), where core::ThermalFusion starts.
[[nodiscard]] std::vector<core::ThermalVec> simulate_open_loop(const core::ThermalFusionConfig& c, const ThermalRecord& r);

/// One step of the filter's run.
struct FilterStep {
  core::ThermalEstimate estimate;
  std::array<core::ThermalFusion::ObservationReport, 3> observations{};
  /// Σ over the step's present observations of −½·(ln 2πs + ν²/s); one beyond the gate counts as if at it.
  double log_likelihood = 0.0;
};

/// The filter over steps [0, end) (end 0: all); `use_winding_sensor_until_s`: the sensor's readings after
/// this time are not used (the honest held-out test, docs/thermal.md).
[[nodiscard]] std::vector<FilterStep> run_filter(
    const core::ThermalFusionConfig& c, const ThermalRecord& r, std::size_t end = 0,
    double use_winding_sensor_until_s = std::numeric_limits<double>::infinity());

}  // namespace rpem::analysis
