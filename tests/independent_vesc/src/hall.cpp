#include "indep_vesc/hall.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "indep_drive/frames.hpp"

namespace indep::vesc {

namespace {

constexpr double kTwoPi = 2.0 * kPi;

/// rad/s of electrical angle → ERPM.
double erpm_of(double rad_s) { return rad_s * 60.0 / kTwoPi; }

/// Into [−π, π), as the firmware keeps its angles.
double norm_rad(double a) {
  a = std::fmod(a, kTwoPi);
  if (a < -kPi) a += kTwoPi;
  if (a >= kPi) a -= kTwoPi;
  return a;
}

/// The shorter signed difference a − b.
double difference(double a, double b) { return norm_rad(a - b); }

double direction_of(double x) { return x < 0.0 ? -1.0 : 1.0; }

/// A table value (1/200 of a turn) as an angle.
double table_rad(int v) { return static_cast<double>(v) / 200.0 * kTwoPi; }

}  // namespace

int hall_state(double theta_el_rad, double offset_rad) {
  int state = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::cos(theta_el_rad - offset_rad - k * kTwoPi / 3.0) > 0.0) state |= 1 << k;
  }
  return state;
}

double hall_sector_centre_rad(int state, double offset_rad) {
  // Going forwards from θ = φ_0 the states are 1, 3, 2, 6, 4, 5, one per 60°.
  static constexpr std::array<int, 6> kOrder{1, 3, 2, 6, 4, 5};
  for (int m = 0; m < 6; ++m) {
    if (kOrder[m] == state) return wrap_2pi(offset_rad + m * kPi / 3.0);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::array<int, 8> detect_hall_table(double offset_rad) {
  std::array<double, 8> s{}, c{};
  std::array<int, 8> n{};
  auto read_at = [&](int deg) {
    const double a = deg * kPi / 180.0;
    const int h = hall_state(a, offset_rad);
    s[h] += std::sin(a);
    c[h] += std::cos(a);
    ++n[h];
  };
  for (int pass = 0; pass < 3; ++pass) {
    for (int deg = 0; deg < 360; ++deg) read_at(deg);
  }
  for (int pass = 0; pass < 3; ++pass) {
    for (int deg = 360; deg >= 0; --deg) read_at(deg);
  }
  std::array<int, 8> table{};
  for (int h = 0; h < 8; ++h) {
    if (n[h] <= 30) {
      table[h] = kHallInvalid;
      continue;
    }
    double deg = std::atan2(s[h], c[h]) * 180.0 / kPi;
    if (deg < 0.0) deg += 360.0;
    if (deg >= 360.0) deg -= 360.0;
    table[h] = static_cast<int>(deg * 200.0 / 360.0);  // truncated, as the uint8_t conversion does
  }
  return table;
}

double HallAngle::correct(double observer_rad, double pll_speed_rad_s, int state, double dt_s, bool override_active,
                          double override_rad) {
  dt_now_ += dt_s;
  const double erpm_abs = std::fabs(erpm_of(pll_speed_rad_s));
  const double hall_rad_s = (kPi / 3.0) / dt_last_;  // signed: the direction of the last transition
  const double hall_erpm_abs = std::fabs(erpm_of(hall_rad_s));
  const bool using_hall = erpm_abs < s_.sl_erpm;

  double angle = observer_rad;
  bool replaced = false;
  const int value = state >= 0 && state < 8 ? s_.table[state] : kHallInvalid;
  nearest_ = false;
  if (value <= 200) {
    const double state_rad = table_rad(value);
    if (prev_ < 0) {
      prev_ = value;
      ang_ = state_rad;
    } else if (value != prev_) {
      int step = value - prev_;  // in table units, the shorter way round
      if (step > 100) step -= 200;
      if (step < -100) step += 200;
      // The time since the previous transition, signed by the direction; on a reversal the last time is kept and
      // only its sign flips.
      if (direction_of(step) == direction_of(dt_last_)) {
        dt_last_ = step > 0 ? dt_now_ : -dt_now_;
      } else {
        dt_last_ = -dt_last_;
      }
      dt_now_ = 0.0;
      // At a transition the rotor is at the boundary: halfway between the two states' angles (integer halving).
      const int boundary = (prev_ + step / 2) % 200;
      ang_ = table_rad(boundary);
    }
    prev_ = value;

    const double slowest = std::max(std::fabs(dt_now_), std::fabs(dt_last_));
    if (erpm_of((kPi / 3.0) / slowest) < s_.interp_erpm) {
      ang_ = state_rad;  // too slow to interpolate: the state's own angle
      nearest_ = true;
    } else {
      const double ahead = difference(ang_, state_rad);
      if (std::fabs(ahead) < kTwoPi / 12.0 || direction_of(ahead) != direction_of(hall_rad_s)) {
        ang_ += hall_rad_s * dt_s;  // on at the speed of the last transitions
      } else {
        ang_ -= 0.01 * ahead;  // 30° past the state's angle: held there, drawn back slowly
      }
    }
    ang_ = norm_rad(ang_);

    // The angle handed on moves at most 1.5× the Hall speed (at least foc_hall_interp_erpm's) per cycle.
    const double max_step = 1.5 * std::max(hall_erpm_abs, s_.interp_erpm) / 60.0 * kTwoPi * dt_s;
    const double gap = difference(ang_, ang_limited_);
    ang_limited_ = std::fabs(gap) < max_step ? ang_ : ang_limited_ + max_step * direction_of(gap);
    ang_limited_ = norm_rad(ang_limited_);

    if (using_hall) {
      angle = ang_limited_;
      replaced = true;
    }
  } else {
    prev_ = -1;  // an invalid state: the angle is not updated
    if (override_active) {
      angle = override_rad;
      replaced = true;
    }
  }

  weight_ = 0.0;
  if (replaced) {
    // Between foc_sl_erpm_start and foc_sl_erpm the two angles are blended, linearly in the PLL's speed.
    weight_ = std::clamp((s_.sl_erpm - erpm_abs) / (s_.sl_erpm - s_.sl_erpm_start), 0.0, 1.0);
    angle = norm_rad(observer_rad + weight_ * difference(angle, observer_rad));
  }
  return angle;
}

}  // namespace indep::vesc
