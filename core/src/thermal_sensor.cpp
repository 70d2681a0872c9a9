#include "rpem/core/thermal_sensor.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {

WindingRate winding_rate(const ThermalNetwork& n, const ThermalRates& rates) noexcept {
  WindingRate r;
  const int w = n.winding;
  r.row.head<kMaxThermalNodes>() = rates.a.row(w).transpose();
  r.row[kMaxThermalNodes + w] = 1.0 / n.capacitance_J_per_K[w];
  r.row[kDynamicThermalStates + static_cast<int>(Calibration::kCoolantError)] = rates.coolant_per_s[w];  // (14.29a)
  r.constant_K_per_s = rates.u[w];
  return r;
}

SensorLagStep sensor_lag_step(double time_constant_s, double dt_s, const ReadingAge& age) noexcept {
  SensorLagStep k;
  if (!(time_constant_s > 0.0) || !(dt_s > 0.0)) return k;
  const double x = dt_s / time_constant_s;
  k.decay = std::exp(-x);
  k.gain_s = time_constant_s * -std::expm1(-x);  // τ_s·(1 − φ) without cancellation at small Δt/τ_s
  // β: the mean of e^{−elapsed/τ_s} over the readings, their elapsed times taken as spread evenly about their
  // mean Δt − ā over a width √(12·v) (eq. 14.22a).
  const double mean_age_s = std::clamp(age.mean_s, 0.0, dt_s);
  const double half_width = std::sqrt(3.0 * std::max(age.variance_s2, 0.0)) / time_constant_s;
  const double sinhc = half_width < 1e-4 ? 1.0 + half_width * half_width / 6.0 : std::sinh(half_width) / half_width;
  k.carry = std::exp(-(dt_s - mean_age_s) / time_constant_s) * sinhc;
  k.rate_s = mean_age_s + time_constant_s * (1.0 - k.carry);  // eq. 14.22
  return k;
}

void SensorLag::advance(const SensorLagStep& k, double rate_K_per_s, double rate_variance_K2_per_s2) noexcept {
  lag_K = k.decay * lag_K + k.gain_s * rate_K_per_s;
  const double sigma =
      k.decay * std::sqrt(std::max(variance_K2, 0.0)) + k.gain_s * std::sqrt(std::max(rate_variance_K2_per_s2, 0.0));
  variance_K2 = sigma * sigma;
}

}  // namespace rpem::core
