#include "rpem/analysis/thermal/sensor_lag.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/analysis/thermal/golden_section.hpp"

namespace rpem::analysis {
namespace {

/// One step of a first-order lag of time constant τ under an input moving linearly over the step (exact for
/// τ ≫ Δt, the trapezoid's mean otherwise); τ = 0 passes the input through.
double lag_step(double y, double u_from, double u_to, double tau_s, double dt_s) {
  const double phi = tau_s > 0.0 ? std::exp(-dt_s / tau_s) : 0.0;
  return phi * y + (1.0 - phi) * 0.5 * (u_from + u_to);
}

/// Σ over the runs (after `warm` steps) of (lag_τs(T_rs) − lag_τr(T_sensor))² at τ_s = e^{log_tau} (eq. 14.25).
double squared_misses(const std::vector<const SensorLagRun*>& runs, std::size_t warm, double log_tau) {
  const double tau_s = std::exp(log_tau);
  double sum = 0.0;
  for (const SensorLagRun* x : runs) {
    double lagged_rs = x->sensor_C.front(), lagged_sensor = x->sensor_C.front();
    for (std::size_t k = 1; k < x->sensor_C.size(); ++k) {
      lagged_rs = lag_step(lagged_rs, x->t_rs_C[k - 1], x->t_rs_C[k], tau_s, x->dt_s[k]);
      lagged_sensor = lag_step(lagged_sensor, x->sensor_C[k - 1], x->sensor_C[k], x->tau_r_s[k], x->dt_s[k]);
      if (k >= warm) sum += (lagged_rs - lagged_sensor) * (lagged_rs - lagged_sensor);
    }
  }
  return sum;
}

/// Student's t quantile at 0.975 for ν degrees of freedom (table for ν ≤ 10, the normal's beyond 30).
double t975(std::size_t nu) {
  constexpr double kTable[] = {0.0, 12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228};
  if (nu <= 10) return kTable[nu];
  return nu <= 30 ? 2.228 - (2.228 - 2.042) * static_cast<double>(nu - 10) / 20.0 : 1.960;
}

}  // namespace

SensorLagEstimate sensor_lag_without_network(const std::vector<SensorLagRun>& runs, double low_s, double high_s,
                                             std::size_t warm) {
  SensorLagEstimate out;
  std::vector<const SensorLagRun*> usable;
  for (const SensorLagRun& r : runs)
    if (r.sensor_C.size() > warm && r.t_rs_C.size() == r.sensor_C.size() && r.tau_r_s.size() == r.sensor_C.size() &&
        r.dt_s.size() == r.sensor_C.size())
      usable.push_back(&r);
  out.runs = usable.size();
  if (usable.empty() || !(low_s > 0.0) || !(high_s > low_s)) return out;
  const double lo = std::log(low_s), hi = std::log(high_s);
  constexpr double kTolerance = 0.005;  // in log τ_s: 0.5 %
  out.tau_s =
      std::exp(golden_section_minimum([&](double x) { return squared_misses(usable, warm, x); }, lo, hi, kTolerance));
  if (usable.size() < 3) return out;
  // Each run's own τ_s: their spread is the estimate's (runs are independent stretches of the log).
  double sum = 0.0, sum2 = 0.0;
  for (const SensorLagRun* r : usable) {
    const std::vector<const SensorLagRun*> one{r};
    const double t =
        std::exp(golden_section_minimum([&](double x) { return squared_misses(one, warm, x); }, lo, hi, kTolerance));
    sum += t, sum2 += t * t;
  }
  const auto m = static_cast<double>(usable.size());
  const double sd = std::sqrt(std::max(0.0, (sum2 - sum * sum / m) / (m - 1.0)));
  const double half = t975(usable.size() - 1) * sd / std::sqrt(m);
  out.lower_s = out.tau_s - half;
  out.upper_s = out.tau_s + half;
  return out;
}

}  // namespace rpem::analysis
