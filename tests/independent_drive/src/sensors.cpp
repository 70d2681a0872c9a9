#include "indep_drive/sensors.hpp"

#include <algorithm>
#include <cmath>

#include "indep_drive/frames.hpp"

namespace indep {

double quantise_bipolar(double v, double full_scale, int bits) {
  if (bits <= 0) return v;
  const double lsb = 2.0 * full_scale / std::ldexp(1.0, bits);
  return std::round(std::clamp(v, -full_scale, full_scale) / lsb) * lsb;
}

Sensors::Sensors(const SensorSpec& spec, const SensorErrors& errors, int pole_pairs, std::uint64_t seed)
    : spec_(spec), errors_(errors), pole_pairs_(pole_pairs), rng_(seed) {}

double Sensors::gauss(double sigma) { return sigma > 0.0 ? sigma * normal_(rng_) : 0.0; }

std::array<double, 3> Sensors::currents(const std::array<double, 3>& i) {
  std::array<double, 3> m{};
  for (std::size_t k = 0; k < 3; ++k) {
    const double sensed = errors_.gain[k] * i[k] + errors_.offset_A[k] + gauss(spec_.current_noise_A);
    m[k] = quantise_bipolar(sensed, spec_.adc_full_scale_A, spec_.adc_bits);
  }
  return m;
}

double Sensors::angle(double theta) const {
  const double shifted = theta + errors_.logged_minus_true_rad;
  if (spec_.encoder_counts_per_rev <= 0) return wrap_2pi(shifted);
  const double step = 2.0 * kPi / static_cast<double>(spec_.encoder_counts_per_rev);
  const double mech = wrap_2pi(shifted / pole_pairs_);
  return wrap_2pi(std::round(mech / step) * step * pole_pairs_);
}

double Sensors::u_dc(double u) {
  const double sensed = u + gauss(spec_.u_dc_noise_V);
  if (spec_.u_dc_adc_bits <= 0) return sensed;
  const double lsb = spec_.u_dc_full_scale_V / std::ldexp(1.0, spec_.u_dc_adc_bits);
  return std::round(std::clamp(sensed, 0.0, spec_.u_dc_full_scale_V) / lsb) * lsb;
}

double Sensors::omega(double w) { return w + gauss(spec_.omega_noise_rad_s); }

double Sensors::temperature(double t) { return t + gauss(spec_.temperature_noise_K); }

}  // namespace indep
