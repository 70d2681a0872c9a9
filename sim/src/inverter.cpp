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

LegSchedule Inverter::schedule(bool rising, double d) const noexcept {
  const double half = half_period_s_;
  LegSchedule s;
  if (d <= 0.0 || d >= 1.0) {
    s.first = s.last = d <= 0.0 ? LegCommand::kLow : LegCommand::kHigh;
    s.switch_s = s.on_s = half;
    return s;
  }
  // Rising half (carrier 0 → 1): high while the carrier is below d; falling half: high once it is.
  s.first = rising ? LegCommand::kHigh : LegCommand::kLow;
  s.last = rising ? LegCommand::kLow : LegCommand::kHigh;
  s.switch_s = (rising ? d : 1.0 - d) * half;
  s.on_s = std::min(s.switch_s + config_.dead_time_s, half);
  return s;
}

double Inverter::leg_voltage(LegCommand c, int sign, double u_dc_V) const noexcept {
  if (c == LegCommand::kBlank) c = sign < 0 ? LegCommand::kHigh : LegCommand::kLow;  // the freewheeling diode
  if (c == LegCommand::kHigh) return sign > 0 ? u_dc_V - config_.v_igbt_V : (sign < 0 ? u_dc_V + config_.v_diode_V : u_dc_V);
  return sign > 0 ? -config_.v_diode_V : (sign < 0 ? config_.v_igbt_V : 0.0);
}

double Inverter::high_fraction(bool rising, double tau, double h, double d, double i) const noexcept {
  if (d <= 0.0) return 0.0;
  if (d >= 1.0) return 1.0;
  if (config_.model == InverterModel::kAveraged) {
    // Mean over the carrier period: one edge per period is delayed by t_dead.
    const double sign = i > 0.0 ? 1.0 : (i < 0.0 ? -1.0 : 0.0);
    return std::clamp(d - sign * config_.dead_time_s / (2.0 * half_period_s_), 0.0, 1.0);
  }
  // The leg is high on one interval [lo, hi]: blanking belongs to it when the current is negative, to
  // the low state when it is positive (without current the edge stays where the PWM puts it).
  const LegSchedule s = schedule(rising, d);
  const double lo = rising ? 0.0 : (i > 0.0 ? s.on_s : s.switch_s);
  const double hi = rising ? (i < 0.0 ? s.on_s : s.switch_s) : half_period_s_;
  if (lo <= tau && tau + h <= hi) return 1.0;  // the common cases first: wholly high…
  if (hi <= tau || tau + h <= lo) return 0.0;  // …or wholly low
  return (std::min(hi, tau + h) - std::max(lo, tau)) / h;
}

core::Vec2 Inverter::mean_voltage(bool rising, double tau_s, double h_s, const Duties& duties, const core::Vec3& i_abc_A,
                                  double u_dc_V) const noexcept {
  core::Vec3 leg;
  for (int x = 0; x < 3; ++x) {
    const double i = i_abc_A[x];
    const double f = high_fraction(rising, tau_s, h_s, duties.d[x], i);
    const int sign = i > 0.0 ? 1 : (i < 0.0 ? -1 : 0);
    leg[x] = f * leg_voltage(LegCommand::kHigh, sign, u_dc_V) + (1.0 - f) * leg_voltage(LegCommand::kLow, sign, u_dc_V);
  }
  return core::clarke(leg);  // the isolated neutral removes the zero sequence
}

}  // namespace rpem::sim
