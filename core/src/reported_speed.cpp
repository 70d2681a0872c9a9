#include "rpem/core/reported_speed.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rpem::core {
namespace {

/// The peak of the impulse response g(t) of k_i/(s² + k_p·s + k_i) [1/s] (docs/derivations.md §13, "Speed at the
/// read"). Overdamped, g = k_i·(e^{−p₁t} − e^{−p₂t})/(p₂ − p₁), at its peak t* = ln(p₂/p₁)/(p₂ − p₁) (14.6 /s at
/// VESC's defaults); critically damped (p₁ = p₂ = k_p/2), g = k_i·t·e^{−pt}, at most k_i/(e·p); underdamped,
/// g = ω_n/√(1 − ζ²)·e^{−ζω_n t}·sin(ω_d t), at most ω_n = √k_i.
double impulse_peak_per_s(const PllGains& pll) noexcept {
  const double kp = pll.kp_per_s, ki = pll.ki_per_s2;
  const double disc = kp * kp - 4.0 * ki;
  if (disc > 0.0) {
    const double root = std::sqrt(disc);
    const double p1 = 0.5 * (kp - root), p2 = 0.5 * (kp + root);
    const double t = std::log(p2 / p1) / root;
    return ki * (std::exp(-p1 * t) - std::exp(-p2 * t)) / root;
  }
  if (disc == 0.0) return ki / (std::numbers::e * 0.5 * kp);
  return std::sqrt(ki);
}

}  // namespace

double window_mean_speed_error_rad_s(const PllGains& pll, double accel_change_rad_s2, double window_s) noexcept {
  if (!pll.given() || !(window_s > 0.0)) return 0.0;
  const double trapezoid = window_s * window_s / 12.0 * impulse_peak_per_s(pll);
  const double dropped = 1.0 / (pll.ki_per_s2 * window_s);
  return std::abs(accel_change_rad_s2) * (trapezoid + dropped);
}

double accel_change_sigma_rad_s2(std::span<double> changes) noexcept {
  const auto finite_end = std::partition(changes.begin(), changes.end(), [](double c) { return std::isfinite(c); });
  const auto count = finite_end - changes.begin();
  if (count < 3) return 0.0;
  for (auto c = changes.begin(); c != finite_end; ++c) *c = std::abs(*c);
  const auto middle = changes.begin() + (count - 1) / 2;  // the lower middle one of an even count
  std::nth_element(changes.begin(), middle, finite_end);
  return 1.4826022185056018 * *middle;  // 1/Φ⁻¹(3/4): σ of a normal over the median of its magnitude
}

}  // namespace rpem::core
