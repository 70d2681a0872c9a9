#include "rpem/analysis/thermal/thermal_replay.hpp"

#include <cmath>
#include <optional>

namespace rpem::analysis {

std::vector<core::ThermalVec> simulate_open_loop(const core::ThermalFusionConfig& c, const ThermalRecord& r) {
  std::vector<core::ThermalVec> out;
  out.reserve(r.steps.size());
  core::ThermalVec t;
  for (std::size_t k = 0; k < r.steps.size(); ++k) {
    const core::ThermalStepData& s = r.steps[k];
    if (r.starts_session(k)) t = core::start_temperatures_C(c, s);  // each session from its own start
    const core::ThermalTransition tr = core::thermal_transition(c.filter.network, s.load);
    t = tr.phi * t + tr.gamma;
    out.push_back(t);
  }
  return out;
}

std::vector<FilterStep> run_filter(const core::ThermalFusionConfig& c, const ThermalRecord& r, std::size_t end,
                                   double use_winding_sensor_until_s) {
  const std::size_t n = end == 0 ? r.steps.size() : std::min(end, r.steps.size());
  // The fusion block needs a base and machine only for its observer, which a replay does not use.
  std::optional<core::ThermalFusion> fusion;  // started afresh at each session's first step
  std::vector<FilterStep> out;
  out.reserve(n);
  const double gate2 = c.filter.gate_sigma * c.filter.gate_sigma;
  for (std::size_t k = 0; k < n; ++k) {
    core::ThermalStepData s = r.steps[k];
    if (r.t_s[k] > use_winding_sensor_until_s) s.winding_sensor_C = std::numeric_limits<double>::quiet_NaN();
    if (r.starts_session(k)) fusion.emplace(c, core::PerUnitBase{}, core::MachineSi{});
    fusion->apply(s);
    FilterStep f;
    f.estimate = fusion->estimate();
    f.observations = fusion->last_observations();
    for (const auto& o : f.observations) {
      // A held reading (eq. 14.28) costs what a refusal at the gate does: a network that made readings look held
      // must not gain by it.
      if (!o.present || o.result == core::ObservationResult::kRejectedInvalid) continue;
      const double z2 = o.result == core::ObservationResult::kAccepted ? o.innovation * o.innovation / o.variance : gate2;
      f.log_likelihood -= 0.5 * (std::log(2.0 * core::kPi * o.variance) + z2);
    }
    out.push_back(f);
  }
  return out;
}

}  // namespace rpem::analysis
