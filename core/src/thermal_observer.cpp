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
  const std::array<Accumulated, 2> acc = learnt_.acc;  // the step's sums stay: its samples were
  learnt_ = Learnt{};
  learnt_.acc = acc;
  before_last_ = learnt_;  // no retraction reaches behind a restart
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
    learnt_.settled[jj] = 0.0;
    return;
  }
  learnt_.settled[jj] += a;
  // κ (eq. 14.6): zero when the other parameter adapted too (their joint equilibrium has no bias).
  const bool other_adapting = (d.flags & flag[1 - jj]) != 0;
  const double kappa_pu = other_adapting ? 0.0 : l.dot(d.gradient.col(o)) / a;
  const double base_j = j == kPsiM ? base_.flux_Wb : base_.impedance_Ohm;
  const double base_o = j == kPsiM ? base_.impedance_Ohm : base_.flux_Wb;
  // σ² (eq. 14.7, 14.8), pu, then SI.
  const double noise = (l * learnt_.eps_cov * l.transpose())(0, 0) / (a * (2.0 - a));
  const double l2 = l.squaredNorm();
  const Vec2& eps_mean = learnt_.eps_mean;
  const Vec2 eps_perp = l2 > 0.0 ? Vec2(eps_mean - (l.dot(eps_mean) / l2) * l.transpose()) : eps_mean;
  const double model = eps_perp.squaredNorm() * l2 / (a * a);
  Accumulated& acc = learnt_.acc[jj];
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
  Learnt& l = learnt_;
  const Vec2 eps = d.epsilon_pu;
  const double tau = config_.residual_time_constant_s;
  l.eps_mean = l.eps_started ? Vec2(l.eps_mean - std::expm1(-dt_s / tau) * (eps - l.eps_mean)) : eps;
  l.eps_started = true;
  l.batch_sum += eps;
  l.batch_dt_s += dt_s;
  double a = 0.0;
  for (int j = 0; j < 2; ++j) a = std::max(a, d.gain.row(j).dot(d.gradient.col(j)));
  l.batch_a += a;
  if (++l.batch_count >= kMaxBatch || l.batch_a >= 0.25) {
    // Batch means, exponentially weighted (West's update), weight w of this batch of M samples.
    const double m = l.batch_count;
    const Vec2 b = l.batch_sum / m;
    if (!l.batch_started) {
      l.batch_mean = b;
      l.eps_cov.setZero();
      l.batch_started = true;
    } else {
      const double w = -std::expm1(-l.batch_dt_s / tau);
      const Vec2 delta = b - l.batch_mean;
      l.batch_mean += w * delta;
      l.eps_cov = (1.0 - w) * (l.eps_cov + (w * m) * delta * delta.transpose());
    }
    l.batch_sum.setZero();
    l.batch_dt_s = l.batch_a = 0.0;
    l.batch_count = 0;
  }
}

void ThermalObserver::retract_last() noexcept {
  // The newest sample's adaptation was taken back (§13, "Mixed windows"): so is what it taught, but for the sums
  // of a step it completed, which the filter has already had.
  const std::array<Accumulated, 2> acc = learnt_.acc;
  learnt_ = before_last_;
  if (stepped_since_last_) learnt_.acc = acc;
  before_last_ = learnt_;
  stepped_since_last_ = false;
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

  if (e.retracted_previous) retract_last();
  before_last_ = learnt_;
  stepped_since_last_ = false;
  if (e.detail.code == StepCode::kAdapted && all_finite(e.epsilon_A)) add_residual(e.detail, dt);
  for (int j = 0; j < 2; ++j) add_parameter(j, e, dt);

  if (losses_.duration_s() < config_.period_s) return false;
  stepped_since_last_ = true;
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
    Accumulated& acc = learnt_.acc[j];
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
      p.valid = 2.0 * acc.adapted_s >= duration && learnt_.settled[j] >= config_.settle_time_constants &&
                all_finite(p.value, p.cross, p.other_held, p.variance);
    }
    acc = Accumulated{};
  }
  return true;
}

}  // namespace rpem::core
