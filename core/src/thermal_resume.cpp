#include "rpem/core/thermal_resume.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/assert.hpp"

namespace rpem::core {

bool fits_network(const ThermalSnapshot& s, const ThermalNetwork& n) noexcept {
  return s.nodes == n.nodes && s.winding == n.winding && s.magnet == n.magnet;
}

namespace {

/// Enough steps for the noise's integration (the transition is exact for a held load, eq. 14.4), few enough that
/// an hour's gap at a fast observer does not hold up the start.
constexpr double kMaxGapSteps = 1000.0;

/// The filter started at the snapshot and predicted `gap_s` under `load`, in steps of at most step_s (at most
/// kMaxGapSteps of them).
ThermalFilter filter_after_gap(const ThermalFilterConfig& c, const ThermalSnapshot& s, ThermalLoad load, double gap_s,
                               double step_s) noexcept {
  ThermalFilter f(c);
  f.set_temperatures(s.t_C, s.p_K2);
  const int steps = static_cast<int>(std::min(std::ceil(gap_s / step_s), kMaxGapSteps));
  load.dt_s = gap_s / std::max(steps, 1);
  for (int k = 0; k < steps; ++k) f.predict(load);
  return f;
}

}  // namespace

ThermalSnapshot across_unknown_load(const ThermalFilterConfig& c, const ThermalSnapshot& s, double gap_s,
                                    double step_s) noexcept {
  RPEM_ASSERT(fits_network(s, c.network), "a snapshot is resumed only by the network it was taken of");
  RPEM_ASSERT(step_s > 0.0, "the gap is predicted in steps of a positive length");
  if (!(gap_s > 0.0)) return s;
  ThermalLoad none;  // the drive stopped: no current, no speed, the same coolant
  none.coolant_C = s.load.coolant_C;
  const ThermalFilter a = filter_after_gap(c, s, none, gap_s, step_s);
  const ThermalFilter b = filter_after_gap(c, s, s.load, gap_s, step_s);  // the drive ran on as it was
  constexpr int kN = kMaxThermalNodes;
  const ThermalVec half = 0.5 * (b.temperature_C() - a.temperature_C());
  ThermalSnapshot out = s;
  out.t_C = a.temperature_C() + half;
  out.p_K2 = 0.5 * (a.covariance().topLeftCorner<kN, kN>() + b.covariance().topLeftCorner<kN, kN>()) +
             half * half.transpose();  // eq. 14.26
  return out;
}

}  // namespace rpem::core
