#include "indep_vesc/observer.hpp"

#include <algorithm>
#include <cmath>

namespace indep::vesc {

double wrap_pi(double a) {
  double w = a - 2.0 * kPi * std::floor((a + kPi) / (2.0 * kPi));  // [−π, π)
  if (w <= -kPi) w += 2.0 * kPi;
  return w;
}

void FluxObserver::update(Vec2 v_ab_V, Vec2 i_ab_A, double dt_s, double gamma) {
  const Vec2 eta = x_ - l_ * i_ab_A;
  const double mismatch = psi_hat_ * psi_hat_ - eta.dot(eta);
  const Vec2 dx = v_ab_V - r_ * i_ab_A + (0.5 * gamma * mismatch) * eta;
  x_ = x_ + dt_s * dx;
  psi_hat_ = std::clamp(psi_hat_ - dt_s * 0.1 * 0.5 * gamma * psi_hat_ * mismatch, 0.3 * psi_, 2.5 * psi_);
  if (!std::isfinite(x_.x) || !std::isfinite(x_.y)) x_ = {0.0, 0.0};
  eta_ = x_ - l_ * i_ab_A;
}

void FluxObserver::force(double angle_rad, Vec2 i_ab_A) {
  eta_ = {psi_hat_ * std::cos(angle_rad), psi_hat_ * std::sin(angle_rad)};
  x_ = eta_ + l_ * i_ab_A;
}

double FluxObserver::angle_rad() const { return std::atan2(eta_.y, eta_.x); }

void Pll::update(double angle_rad, double dt_s) {
  const double e = wrap_pi(angle_rad - angle_);
  angle_ = wrap_pi(angle_ + (speed_ + kp_ * e) * dt_s);
  speed_ += ki_ * e * dt_s;
}

void Pll::clamp_speed(double max_abs_rad_s) { speed_ = std::clamp(speed_, -max_abs_rad_s, max_abs_rad_s); }

}  // namespace indep::vesc
