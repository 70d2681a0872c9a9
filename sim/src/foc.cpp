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
      i_max_A_(config.max_current_A > 0.0 ? config.max_current_A : base_.current_A),
      was_speed_control_(config.speed_control) {}

void FocController::reset() noexcept {
  mtpa_torque_Nm_ = 0.0;
  mtpa_i_A_.setZero();
  integral_V_.setZero();
  speed_integral_Nm_ = 0.0;
  last_torque_ref_Nm_ = 0.0;
  rotation_.reset();
}

void FocController::preset(const core::Vec2& u_dq_V, double omega_el_rad_s) noexcept {
  integral_V_ = u_dq_V - core::Vec2(0.0, omega_el_rad_s * nominal_.psi_m_Wb);  // less the feed-forward at i = 0
}

core::Vec2 FocController::field_weaken(core::Vec2 i_ref, double torque_Nm, double omega, double u_limit) const noexcept {
  // Voltage ellipse of the nominal model (R neglected; the margin covers it):
  //   (ω·L_q·i_q)² + (ω·(L_d·i_d + ψ_m))² ≤ u_limit²
  const double l_d = nominal_.l_d_H, l_q = nominal_.l_q_H, psi = nominal_.psi_m_Wb;
  const double flux_limit2 = omega == 0.0 ? 1e30 : (u_limit / omega) * (u_limit / omega);
  const double psi_q = l_q * i_ref[1];
  const double psi_d0 = l_d * i_ref[0] + psi;
  // Inside both the voltage ellipse and the current circle nothing below changes i_ref: skip the roots.
  if (psi_d0 * psi_d0 + psi_q * psi_q <= flux_limit2 && i_ref.squaredNorm() <= i_max_A_ * i_max_A_) return i_ref;
  const double psi_d_max = std::sqrt(std::max(0.0, flux_limit2 - psi_q * psi_q));
  const double i_d_fw = (psi_d_max - psi) / l_d;
  if (i_d_fw < i_ref[0]) {
    // Weaken the field and re-solve i_q for the torque at the new i_d (the reluctance torque grows).
    i_ref[0] = std::max(i_d_fw, -i_max_A_);
    i_ref[1] = torque_Nm / (1.5 * nominal_.rated.pole_pairs * (psi + (l_d - l_q) * i_ref[0]));
  }
  // Current limit first, then whatever q current the voltage still allows at that i_d.
  double iq_max = std::sqrt(std::max(0.0, i_max_A_ * i_max_A_ - i_ref[0] * i_ref[0]));
  const double psi_d = l_d * i_ref[0] + psi;
  iq_max = std::min(iq_max, std::sqrt(std::max(0.0, flux_limit2 - psi_d * psi_d)) / l_q);
  i_ref[1] = std::clamp(i_ref[1], -iq_max, iq_max);
  return i_ref;
}

FocOutput FocController::step(const FocInput& in) noexcept {
  FocOutput out;
  const double t = config_.period_s;
  const double omega = in.omega_el_rad_s;
  const int p = nominal_.rated.pole_pairs;

  core::Vec2 i_ref = in.current_ref_A;
  if (in.current_override) {
    last_torque_ref_Nm_ = 0.0;
  } else {
    // Torque reference: commanded, or from the speed PI (mechanical units).
    double torque_ref = in.torque_ref_Nm;
    const double torque_max = 1.5 * p * nominal_.psi_m_Wb * i_max_A_;
    if (in.speed_control) {
      // Entering speed mode (from torque mode, open loop or bridge off) starts the integrator at the last
      // torque reference: bumpless.
      if (!was_speed_control_) speed_integral_Nm_ = last_torque_ref_Nm_;
      const double w = 2.0 * core::kPi * config_.speed_bandwidth_Hz;
      const double kp = config_.inertia_kgm2 * w, ki = kp * w / 4.0;
      const double error = (in.speed_ref_el_rad_s - omega) / p;
      const double unsat = kp * error + speed_integral_Nm_ + ki * error * t;
      if (std::abs(unsat) < torque_max) speed_integral_Nm_ += ki * error * t;
      torque_ref = in.torque_ref_Nm + std::clamp(kp * error + speed_integral_Nm_, -torque_max, torque_max);
    }
    torque_ref = std::clamp(torque_ref, -torque_max, torque_max);
    out.torque_ref_Nm = torque_ref;
    last_torque_ref_Nm_ = torque_ref;

    // Current references: MTPA (eq_refcurrents), then field weakening and the current limit.
    if (torque_ref != mtpa_torque_Nm_) {  // eq_refcurrents only when the torque reference moves
      mtpa_torque_Nm_ = torque_ref;
      mtpa_i_A_ = core::mtpa_reference(nominal_pu_, base_.torque_pu(torque_ref)) * base_.current_A;
    }
    i_ref = mtpa_i_A_;
    const double u_max_fw = in.u_dc_V * core::kInvSqrt3;
    if (config_.field_weakening) i_ref = field_weaken(i_ref, torque_ref, omega, config_.voltage_margin * u_max_fw);
  }
  was_speed_control_ = in.speed_control && !in.current_override;
  out.i_ref_A = i_ref;
  const double u_max = in.u_dc_V * core::kInvSqrt3;

  // dq current PI with decoupling.
  const core::Rotation rot = rotation_.at(in.theta_el_rad);
  const core::Vec2 i_dq = core::park(core::clarke(in.i_abc_A), rot);
  const double wc = 2.0 * core::kPi * config_.current_bandwidth_Hz;
  const core::Vec2 kp(wc * nominal_.l_d_H, wc * nominal_.l_q_H);
  const double ki = wc * nominal_.r_s_Ohm;
  const core::Vec2 error = i_ref - i_dq;
  // Decoupling from the references: no extra feedback path through the measured currents.
  const core::Vec2 feedforward =
      in.decouple ? core::Vec2(-omega * nominal_.l_q_H * i_ref[1], omega * (nominal_.l_d_H * i_ref[0] + nominal_.psi_m_Wb))
                  : core::Vec2::Zero();
  const core::Vec2 candidate_integral = integral_V_ + ki * t * error;
  core::Vec2 u_dq = kp.cwiseProduct(error) + candidate_integral + feedforward;

  const double magnitude2 = u_dq.squaredNorm();
  if (magnitude2 > u_max * u_max) {
    u_dq *= u_max / std::sqrt(magnitude2);  // keep the direction; hold the integrators (anti-windup)
    out.voltage_limited = true;
  } else {
    integral_V_ = candidate_integral;
  }

  // The command acts during the next period: rotate at the mid-point of that interval.
  out.u_ab_V = core::inverse_park(u_dq, core::compose(rot, core::small_rotation(1.5 * omega * t)));
  return out;
}

}  // namespace rpem::sim
