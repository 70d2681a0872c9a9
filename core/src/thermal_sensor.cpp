#include "rpem/core/thermal_sensor.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {

WindingRate winding_rate(const ThermalNetwork& n, const ThermalRates& rates) noexcept {
  WindingRate r;
  const int w = n.winding;
  r.row.head<kMaxThermalNodes>() = rates.a.row(w).transpose();
  r.row[kMaxThermalNodes + w] = 1.0 / n.capacitance_J_per_K[w];
  r.constant_K_per_s = rates.u[w];
  return r;
}

SensorLagStep sensor_lag_step(double time_constant_s, double dt_s) noexcept {
  SensorLagStep k;
  if (!(time_constant_s > 0.0) || !(dt_s > 0.0)) return k;
  const double x = dt_s / time_constant_s;
  k.decay = std::exp(-x);
  const double one_minus = -std::expm1(-x);  // 1 − φ without cancellation at small Δt/τ_s
  k.gain_s = time_constant_s * one_minus;
  k.carry = one_minus / x;
  k.rate_s = 0.5 * dt_s + time_constant_s * (1.0 - k.carry);  // eq. 14.22
  return k;
}

void SensorLag::advance(const SensorLagStep& k, double rate_K_per_s, double rate_variance_K2_per_s2) noexcept {
  lag_K = k.decay * lag_K + k.gain_s * rate_K_per_s;
  const double sigma =
      k.decay * std::sqrt(std::max(variance_K2, 0.0)) + k.gain_s * std::sqrt(std::max(rate_variance_K2_per_s2, 0.0));
  variance_K2 = sigma * sigma;
}

}  // namespace rpem::core
