#include "rpem/sim/inverter.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/frames.hpp"

namespace rpem::sim {

Duties modulate(const core::Vec2& u_ab_V, double u_dc_V, bool third_harmonic) noexcept {
  const core::Vec3 u_abc = core::inverse_clarke(u_ab_V);
  double u_zero = 0.0;
  const double amplitude2 = u_ab_V.squaredNorm();
  if (third_harmonic && amplitude2 > 0.0) {
    // −(U/6)·cos 3φ with cos φ = u_a/U:  −(1/6)·(4·u_a³/U² − 3·u_a) = u_a·(1/2 − (2/3)·u_a²/U²)
    const double ua = u_abc[0];
    u_zero = ua * (0.5 - (2.0 / 3.0) * ua * ua / amplitude2);
  }
  Duties out;
  const double inv_u_dc = 1.0 / u_dc_V;
  for (int x = 0; x < 3; ++x) out.d[x] = std::clamp(0.5 + (u_abc[x] + u_zero) * inv_u_dc, 0.0, 1.0);
  return out;
}

Inverter::Inverter(const InverterConfig& config) noexcept
    : config_(config), half_period_s_(0.5 / config.switching_frequency_Hz) {}

double Inverter::high_fraction(bool rising, double tau, double h, double d, double i) const noexcept {
  if (d <= 0.0) return 0.0;
  if (d >= 1.0) return 1.0;
  const double half = half_period_s_;
  const double td = config_.dead_time_s;
  if (config_.model == InverterModel::kAveraged) {
    // Mean over the carrier period: one edge per period is delayed by t_dead.
    const double sign = i > 0.0 ? 1.0 : (i < 0.0 ? -1.0 : 0.0);
    return std::clamp(d - sign * td / (2.0 * half), 0.0, 1.0);
  }
  // Rising half (carrier 0 → 1): high on [0, d·half], the falling edge is delayed when i < 0.
  // Falling half (carrier 1 → 0): high on [(1 − d)·half, half], the rising edge is delayed when i > 0.
  double lo = 0.0, hi = 0.0;
  if (rising) {
    hi = std::min(d * half + (i < 0.0 ? td : 0.0), half);
  } else {
    lo = std::min((1.0 - d) * half + (i > 0.0 ? td : 0.0), half);
    hi = half;
  }
  if (lo <= tau && tau + h <= hi) return 1.0;  // the common cases first: wholly high…
  if (hi <= tau || tau + h <= lo) return 0.0;   // …or wholly low
  return (std::min(hi, tau + h) - std::max(lo, tau)) / h;
}

core::Vec2 Inverter::mean_voltage(bool rising, double tau_s, double h_s, const Duties& duties,
                                  const core::Vec3& i_abc_A, double u_dc_V) const noexcept {
  core::Vec3 leg;
  for (int x = 0; x < 3; ++x) {
    const double i = i_abc_A[x];
    const double f = high_fraction(rising, tau_s, h_s, duties.d[x], i);
    // Conducting device: i > 0 flows through the upper transistor (high) or lower diode (low).
    const double v_high = i > 0.0 ? u_dc_V - config_.v_igbt_V : (i < 0.0 ? u_dc_V + config_.v_diode_V : u_dc_V);
    const double v_low = i > 0.0 ? -config_.v_diode_V : (i < 0.0 ? config_.v_igbt_V : 0.0);
    leg[x] = f * v_high + (1.0 - f) * v_low;
  }
  return core::clarke(leg);  // the isolated neutral removes the zero sequence
}

}  // namespace rpem::sim
