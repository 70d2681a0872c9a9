#include "rpem/core/thermal_observer.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {

ThermalObserver::ThermalObserver(const ThermalObserverConfig& config, const PerUnitBase& base, const MachineSi& machine,
                                 const LossBase& loss_base, double coolant_C) noexcept {
  reconfigure(config, base, machine, loss_base, coolant_C);
}

void ThermalObserver::reconfigure(const ThermalObserverConfig& config, const PerUnitBase& base, const MachineSi& machine,
                                  const LossBase& loss_base, double coolant_C) noexcept {
  config_ = config;
  base_ = base;
  machine_ = machine;
  loss_base_ = loss_base;
  coolant_C_ = coolant_C;
}

void ThermalObserver::restart() noexcept {
  settled_ = {};
  eps_started_ = batch_started_ = false;
  eps_mean_.setZero();
  eps_cov_.setZero();
  batch_sum_.setZero();
  batch_mean_.setZero();
  batch_dt_s_ = batch_a_ = 0.0;
  batch_count_ = 0;
}

void ThermalObserver::add_parameter(int j, const Estimate& e, double dt_s) noexcept {
  const auto jj = static_cast<std::size_t>(j);
  const std::uint16_t flag[2] = {step_flag::kPsiMActive, step_flag::kRsActive};
  const EstimatorOutput& d = e.detail;
  // An excluded or skipped sample (regime.hpp, the outlier test) is predicted and changes nothing: the
  // settling pauses over it. Anything else that does not adapt j (resync, scheduled out) restarts it.
  if (d.code == StepCode::kExcluded || d.code == StepCode::kOutlier) return;
  const bool adapting = d.code == StepCode::kAdapted && (d.flags & flag[jj]) != 0;
  const int o = 1 - j;
  const Eigen::Matrix<double, 1, 2> l = d.gain.row(j);
  const double a = l.dot(d.gradient.col(j));
  if (!adapting || !(a > 0.0 && a < 2.0)) {  // a ≥ 2: the update overshoots, no stationary variance
    settled_[jj] = 0.0;
    return;
  }
  settled_[jj] += a;
  // κ (eq. 14.6): zero when the other parameter adapted too (their joint equilibrium has no bias).
  const bool other_adapting = (d.flags & flag[1 - jj]) != 0;
  const double kappa_pu = other_adapting ? 0.0 : l.dot(d.gradient.col(o)) / a;
  const double base_j = j == kPsiM ? base_.flux_Wb : base_.impedance_Ohm;
  const double base_o = j == kPsiM ? base_.impedance_Ohm : base_.flux_Wb;
  // σ² (eq. 14.7, 14.8), pu, then SI.
  const double noise = (l * eps_cov_ * l.transpose())(0, 0) / (a * (2.0 - a));
  const double l2 = l.squaredNorm();
  const Vec2 eps_perp = l2 > 0.0 ? Vec2(eps_mean_ - (l.dot(eps_mean_) / l2) * l.transpose()) : eps_mean_;
  const double model = eps_perp.squaredNorm() * l2 / (a * a);
  Accumulated& acc = acc_[jj];
  acc.adapted_s += dt_s;
  acc.value += j == kPsiM ? e.psi_m_Wb : e.r_s_Ohm;
  acc.other += j == kPsiM ? e.r_s_Ohm : e.psi_m_Wb;
  acc.cross += kappa_pu * base_j / base_o;
  acc.variance_noise += noise * base_j * base_j;
  acc.variance += (noise + model) * base_j * base_j;
  acc.tau += dt_s / a;
  ++acc.samples;
}

void ThermalObserver::add_residual(const EstimatorOutput& d, double dt_s) noexcept {
  const Vec2 eps = d.epsilon_pu;
  const double tau = config_.residual_time_constant_s;
  eps_mean_ = eps_started_ ? Vec2(eps_mean_ - std::expm1(-dt_s / tau) * (eps - eps_mean_)) : eps;
  eps_started_ = true;
  batch_sum_ += eps;
  batch_dt_s_ += dt_s;
  double a = 0.0;
  for (int j = 0; j < 2; ++j) a = std::max(a, d.gain.row(j).dot(d.gradient.col(j)));
  batch_a_ += a;
  if (++batch_count_ >= kMaxBatch || batch_a_ >= 0.25) {
    // Batch means, exponentially weighted (West's update), weight w of this batch of M samples.
    const double m = batch_count_;
    const Vec2 b = batch_sum_ / m;
    if (!batch_started_) {
      batch_mean_ = b;
      eps_cov_.setZero();
      batch_started_ = true;
    } else {
      const double w = -std::expm1(-batch_dt_s_ / tau);
      const Vec2 delta = b - batch_mean_;
      batch_mean_ += w * delta;
      eps_cov_ = (1.0 - w) * (eps_cov_ + (w * m) * delta * delta.transpose());
    }
    batch_sum_.setZero();
    batch_dt_s_ = batch_a_ = 0.0;
    batch_count_ = 0;
  }
}

bool ThermalObserver::add(const Estimate& e, const ThermalSample& s) noexcept {
  const double dt = std::isfinite(s.dt_s) && s.dt_s > 0.0 ? s.dt_s : 0.0;
  // The coolant is an input the step integrates: a reading holds until the next one (a zero-order hold of a
  // slow temperature that a log or a bus may give less often than the currents).
  if (std::isfinite(s.coolant_C)) {
    measured_coolant_C_ = s.coolant_C;
    coolant_read_ = true;
  }
  const double coolant = std::isfinite(measured_coolant_C_) ? measured_coolant_C_ : coolant_C_;
  const Vec2 i = e.i_meas_A;
  const double omega = base_.omega_el_rad_s_of(e.speed_pu);
  // The stator flux linkage of the dq model with the current ψ̂m (docs/derivations.md §14, "Losses").
  const Vec2 psi(e.psi_m_Wb + machine_.l_d_H * i[0], machine_.l_q_H * i[1]);
  if (all_finite(i, omega, psi, coolant)) losses_.add(loss_base_, dt, i, omega, psi, coolant);
  if (std::isfinite(s.winding_sensor_C)) {
    const double w = std::max(dt, 1e-9), elapsed = losses_.duration_s();  // read at this sample's time
    sensor_sum_ += s.winding_sensor_C * w;
    sensor_time_ += w;
    sensor_elapsed_ += elapsed * w;
    sensor_elapsed_sq_ += elapsed * elapsed * w;
  }

  if (e.detail.code == StepCode::kAdapted && all_finite(e.epsilon_A)) add_residual(e.detail, dt);
  for (int j = 0; j < 2; ++j) add_parameter(j, e, dt);

  if (losses_.duration_s() < config_.period_s) return false;
  const double duration = losses_.duration_s();
  step_.t_ns = e.t_ns;
  step_.load = losses_.take();
  step_.psi_m_Wb = e.psi_m_Wb;
  step_.r_s_Ohm = e.r_s_Ohm;
  step_.winding_sensor_C = sensor_time_ > 0.0 ? sensor_sum_ / sensor_time_ : std::numeric_limits<double>::quiet_NaN();
  step_.winding_sensor_age = ReadingAge{};
  step_.coolant_read = coolant_read_;
  coolant_read_ = false;
  if (sensor_time_ > 0.0) {
    const double mean_elapsed = sensor_elapsed_ / sensor_time_;
    step_.winding_sensor_age = {std::max(0.0, duration - mean_elapsed),
                                std::max(0.0, sensor_elapsed_sq_ / sensor_time_ - mean_elapsed * mean_elapsed)};
  }
  sensor_sum_ = sensor_time_ = sensor_elapsed_ = sensor_elapsed_sq_ = 0.0;
  for (std::size_t j = 0; j < 2; ++j) {
    Accumulated& acc = acc_[j];
    ParameterObservation& p = step_.parameter[j];
    p = ParameterObservation{};
    if (acc.samples > 0) {
      const double n = 1.0 / acc.samples;
      p.value = acc.value * n;
      p.cross = acc.cross * n;
      p.other_held = acc.other * n;
      p.variance = acc.variance * n;
      p.variance_noise = acc.variance_noise * n;
      p.time_constant_s = acc.tau * n;
      p.sample_dt_s = acc.adapted_s * n;
      p.valid = 2.0 * acc.adapted_s >= duration && settled_[j] >= config_.settle_time_constants &&
                all_finite(p.value, p.cross, p.other_held, p.variance);
    }
    acc = Accumulated{};
  }
  return true;
}

}  // namespace rpem::core
