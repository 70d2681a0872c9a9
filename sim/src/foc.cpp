#include "rpem/sim/foc.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/frames.hpp"
#include "rpem/core/machine.hpp"

namespace rpem::sim {

FocController::FocController(const FocConfig& config, const core::MachineSi& nominal) noexcept
    : config_(config),
      nominal_(nominal),
      base_(core::PerUnitBase::from_rated(nominal.rated)),
      nominal_pu_(core::to_pu(base_, nominal)),
      i_max_A_(config.max_current_A > 0.0 ? config.max_current_A : base_.current_A) {}

void FocController::reset() noexcept {
  mtpa_torque_Nm_ = 0.0;
  mtpa_i_A_.setZero();
  integral_V_.setZero();
  speed_integral_Nm_ = 0.0;
  i_d_fw_A_ = 0.0;
}

FocOutput FocController::step(const FocInput& in) noexcept {
  FocOutput out;
  const double t = config_.period_s;
  const double omega = in.omega_el_rad_s;
  const int p = nominal_.rated.pole_pairs;

  // Torque reference: commanded, or from the speed PI (mechanical units).
  double torque_ref = in.torque_ref_Nm;
  const double torque_max = 1.5 * p * nominal_.psi_m_Wb * i_max_A_;
  if (config_.speed_control) {
    const double w = 2.0 * core::kPi * config_.speed_bandwidth_Hz;
    const double kp = config_.inertia_kgm2 * w, ki = kp * w / 4.0;
    const double error = (in.speed_ref_el_rad_s - omega) / p;
    const double unsat = kp * error + speed_integral_Nm_ + ki * error * t;
    if (std::abs(unsat) < torque_max) speed_integral_Nm_ += ki * error * t;
    torque_ref = in.torque_ref_Nm + std::clamp(kp * error + speed_integral_Nm_, -torque_max, torque_max);
  }
  torque_ref = std::clamp(torque_ref, -torque_max, torque_max);
  out.torque_ref_Nm = torque_ref;

  // Current references: MTPA (eq_refcurrents), then field weakening and the current limit.
  if (torque_ref != mtpa_torque_Nm_) {  // eq_refcurrents only when the torque reference moves
    mtpa_torque_Nm_ = torque_ref;
    mtpa_i_A_ = core::mtpa_reference(nominal_pu_, base_.torque_pu(torque_ref)) * base_.current_A;
  }
  core::Vec2 i_ref = mtpa_i_A_;
  if (config_.field_weakening) i_ref[0] = std::min(i_ref[0], i_d_fw_A_);
  i_ref[0] = std::max(i_ref[0], -i_max_A_);
  const double iq_max = std::sqrt(std::max(0.0, i_max_A_ * i_max_A_ - i_ref[0] * i_ref[0]));
  i_ref[1] = std::clamp(i_ref[1], -iq_max, iq_max);
  out.i_ref_A = i_ref;

  // dq current PI with decoupling.
  const core::Rotation rot = core::Rotation::of(in.theta_el_rad);
  const core::Vec2 i_dq = core::park(core::clarke(in.i_abc_A), rot);
  const double wc = 2.0 * core::kPi * config_.current_bandwidth_Hz;
  const core::Vec2 kp(wc * nominal_.l_d_H, wc * nominal_.l_q_H);
  const double ki = wc * nominal_.r_s_Ohm;
  const core::Vec2 error = i_ref - i_dq;
  const core::Vec2 feedforward(-omega * nominal_.l_q_H * i_dq[1],
                               omega * (nominal_.l_d_H * i_dq[0] + nominal_.psi_m_Wb));
  const core::Vec2 candidate_integral = integral_V_ + ki * t * error;
  core::Vec2 u_dq = kp.cwiseProduct(error) + candidate_integral + feedforward;

  const double u_max = in.u_dc_V / core::kSqrt3;
  const double magnitude = u_dq.norm();
  if (magnitude > u_max) {
    u_dq *= u_max / magnitude;  // keep the direction; hold the integrators (anti-windup)
    out.voltage_limited = true;
  } else {
    integral_V_ = candidate_integral;
  }
  if (config_.field_weakening) {
    // |u| ≈ ω·L_d·|Δi_d| sensitivity: an integrator with ~100 rad/s of loop bandwidth at rated speed.
    const double k_fw = 100.0 / (base_.omega_el_rad_s * nominal_.l_d_H);
    i_d_fw_A_ += k_fw * (config_.voltage_margin * u_max - magnitude) * t;
    i_d_fw_A_ = std::clamp(i_d_fw_A_, -i_max_A_, 0.0);
  }

  // The command acts during the next period: rotate at the mid-point of that interval.
  out.u_ab_V = core::inverse_park(u_dq, core::compose(rot, core::small_rotation(1.5 * omega * t)));
  return out;
}

}  // namespace rpem::sim
