#include "rpem/sim/plant.hpp"

namespace rpem::sim {
PmsmPlant::PmsmPlant(int pole_pairs, Magnetics magnetics, MechanicsConfig mechanics) noexcept
    : pole_pairs_(pole_pairs), magnetics_(std::move(magnetics)), mechanics_(mechanics) {}

void PmsmPlant::reset(const core::Vec2& i_A, double theta_el_rad, double omega_el_rad_s, const PlantParameters& p) noexcept {
  state_.theta_el_rad = theta_el_rad;
  state_.omega_el_rad_s = omega_el_rad_s;
  i_flux_A_ = i_A;
  parameters_ = p;
  magnetics_.prepare(p);
  periods_since_exact_rotation_ = 0;
  begin_period(p, h_s_, 0.0);
  state_.psi_Wb = magnetics_.flux(i_A);
  state_.i_A = stator_current(state_.psi_Wb, i_flux_A_, omega_el_rad_s);
  update_torque();
  torque_integral_Nms_ = 0.0;
}

void PmsmPlant::begin_period(const PlantParameters& p, double h_s, double load_torque_Nm) noexcept {
  const bool magnetics_changed =
      p.psi_m_Wb != parameters_.psi_m_Wb || p.l_d_H != parameters_.l_d_H || p.l_q_H != parameters_.l_q_H;
  parameters_ = p;
  h_s_ = h_s;
  load_torque_Nm_ = load_torque_Nm;
  if (periods_since_exact_rotation_++ % 32 == 0) rotation_ = core::Rotation::of(state_.theta_el_rad);
  step_rotation_ = core::small_rotation(state_.omega_el_rad_s * h_s);
  if (magnetics_changed) {
    // A scenario's parameter step keeps the current continuous (as a current-state model does) and
    // moves the flux, rather than a current jump of Δψm/L_d.
    magnetics_.prepare(p);
    state_.psi_Wb = magnetics_.flux(i_flux_A_);
  }
}

void PmsmPlant::set_speed(double omega_el_rad_s) noexcept {
  if (mechanics_.dynamometer) state_.omega_el_rad_s = omega_el_rad_s;
}

core::Vec2 PmsmPlant::stator_current(const core::Vec2& psi, const core::Vec2& i_flux, double omega) const noexcept {
  if (parameters_.r_fe_Ohm <= 0.0) return i_flux;
  return i_flux + (omega / parameters_.r_fe_Ohm) * core::Vec2(-psi[1], psi[0]);
}

core::Vec2 PmsmPlant::derivative(const core::Vec2& psi, const core::Vec2& i, const core::Vec2& u_dq,
                                 double omega) const noexcept {
  const double r = parameters_.r_s_Ohm;
  return {u_dq[0] - r * i[0] + omega * psi[1], u_dq[1] - r * i[1] - omega * psi[0]};
}

void PmsmPlant::step(const core::Vec2& u_ab_V) noexcept {
  const double h = h_s_;
  const double omega = state_.omega_el_rad_s;
  const core::Rotation r0 = rotation_;
  const core::Rotation r1 = core::compose(r0, step_rotation_);

  // Heun: predictor at t, corrector at t + h.
  const core::Vec2 k1 = derivative(state_.psi_Wb, state_.i_A, core::park(u_ab_V, r0), omega);
  const core::Vec2 psi_pred = state_.psi_Wb + h * k1;
  const core::Vec2 i_flux_pred = magnetics_.current(psi_pred, i_flux_A_);
  const core::Vec2 i_pred = stator_current(psi_pred, i_flux_pred, omega);
  const core::Vec2 k2 = derivative(psi_pred, i_pred, core::park(u_ab_V, r1), omega);
  state_.psi_Wb += 0.5 * h * (k1 + k2);
  i_flux_A_ = magnetics_.current(state_.psi_Wb, i_flux_pred);
  state_.i_A = stator_current(state_.psi_Wb, i_flux_A_, omega);

  update_torque();
  if (!mechanics_.dynamometer) state_.omega_el_rad_s += h * acceleration(state_.torque_Nm, omega) * pole_pairs_;
  state_.theta_el_rad += omega * h;
  rotation_ = r1;
}

void PmsmPlant::freewheel(int steps) noexcept {
  const double h = h_s_;
  i_flux_A_.setZero();
  state_.i_A.setZero();
  state_.psi_Wb = magnetics_.flux(i_flux_A_);
  state_.torque_Nm = 0.0;
  for (int s = 0; s < steps; ++s) {
    const double omega = state_.omega_el_rad_s;
    if (!mechanics_.dynamometer) state_.omega_el_rad_s += h * acceleration(0.0, omega) * pole_pairs_;
    state_.theta_el_rad += omega * h;
    rotation_ = core::compose(rotation_, rotation_by(omega * h));
  }
}

void PmsmPlant::update_torque() noexcept {
  state_.torque_Nm = 1.5 * pole_pairs_ * (state_.psi_Wb[0] * state_.i_A[1] - state_.psi_Wb[1] * state_.i_A[0]);
}

double PmsmPlant::acceleration(double torque_Nm, double omega) const noexcept {
  const double omega_mech = omega / pole_pairs_;
  return (torque_Nm - load_torque_Nm_ - mechanics_.friction_Nms * omega_mech) / mechanics_.inertia_kgm2;
}

void PmsmPlant::move_to(const core::Vec2& psi_Wb, const core::Vec2& i_flux_guess_A, double dt_s) noexcept {
  const double omega = period_speed();
  const double torque_before = state_.torque_Nm;
  state_.psi_Wb = psi_Wb;
  i_flux_A_ = magnetics_.current(psi_Wb, i_flux_guess_A);
  state_.i_A = stator_current(psi_Wb, i_flux_A_, omega);
  update_torque();
  torque_integral_Nms_ += 0.5 * (torque_before + state_.torque_Nm) * dt_s;
  const double angle = omega * dt_s;
  state_.theta_el_rad += angle;
  rotation_ = core::compose(rotation_, rotation_by(angle));
}

void PmsmPlant::end_period() noexcept {
  const double period_s = h_s_;
  const double torque_mean = torque_integral_Nms_ / period_s;
  torque_integral_Nms_ = 0.0;
  if (mechanics_.dynamometer) return;
  const double omega_before = state_.omega_el_rad_s, turned = period_speed() * period_s;
  acceleration_el_ = acceleration(torque_mean, omega_before) * pole_pairs_;
  state_.omega_el_rad_s += period_s * acceleration_el_;
  const double correction = 0.5 * (omega_before + state_.omega_el_rad_s) * period_s - turned;
  state_.theta_el_rad += correction;
  rotation_ = core::compose(rotation_, rotation_by(correction));
}

core::Vec3 PmsmPlant::phase_currents() const noexcept {
  return core::inverse_clarke(core::inverse_park(state_.i_A, rotation_));
}

}  // namespace rpem::sim
