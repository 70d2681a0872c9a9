#pragma once
// IPMSM plant in the rotor frame, SI, flux linkages as states (so flux maps with cross-saturation
// fit without differential inductances):
//   dψ_d/dt = u_d − R_s·i_d + ω·ψ_q,   dψ_q/dt = u_q − R_s·i_q − ω·ψ_d
//   T_e = (3/2)·p·(ψ_d·i_q − ψ_q·i_d)
// With iron loss (R_fe > 0) the induced voltage e = ω·J·ψ drives a parallel current e/R_fe that the
// stator current also supplies: i_s = i(ψ) + ω·J·ψ/R_fe.
// Two integrators: fixed steps of Heun's method (step(); the stator-frame voltage is constant over each
// step and rotates into the rotor frame at both ends), or EdgeIntegrator's exact or error-controlled
// segments between switching instants, which move the state with move_to() and end_period().
// Mechanics: imposed speed (dynamometer, as on the bench) or J·dω_m/dt = T_e − T_load − B·ω_m.

#include <cmath>

#include "rpem/core/frames.hpp"
#include "rpem/core/types.hpp"
#include "rpem/sim/magnetics.hpp"

namespace rpem::sim {

struct MechanicsConfig {
  bool dynamometer = true;     ///< speed imposed by the scenario
  double inertia_kgm2 = 0.01;  ///< J (inertia mode)
  double friction_Nms = 0.0;   ///< B (inertia mode)
};

struct PlantState {
  core::Vec2 psi_Wb = core::Vec2::Zero();  ///< rotor-frame flux linkage
  core::Vec2 i_A = core::Vec2::Zero();     ///< rotor-frame stator current
  double theta_el_rad = 0.0;               ///< unwrapped electrical angle
  double omega_el_rad_s = 0.0;
  double torque_Nm = 0.0;
};

/// The rotation by a small angle (a Taylor series within core::small_rotation's range, libm beyond).
[[nodiscard]] inline core::Rotation rotation_by(double angle_rad) noexcept {
  return std::abs(angle_rad) <= core::RotationTracker::kLargestIncrement_rad ? core::small_rotation(angle_rad)
                                                                             : core::Rotation::of(angle_rad);
}

/// Phase currents a, b, c and their rates of change at one instant.
struct PhaseCurrents {
  core::Vec3 i_A = core::Vec3::Zero();
  core::Vec3 rate_A_s = core::Vec3::Zero();
};

/// The phase currents of the rotor-frame current i_dq (changing at di_dq/dt) at the rotor angle of
/// `r`, turning at ω: i_αβ = R(ϑ)·i_dq, di_αβ/dt = R(ϑ)·(di_dq/dt + ω·J·i_dq).
[[nodiscard]] inline PhaseCurrents phase_currents(const core::Vec2& i_dq, const core::Vec2& di_dq, const core::Rotation& r,
                                                  double omega) noexcept {
  const core::Vec2 turning(di_dq[0] - omega * i_dq[1], di_dq[1] + omega * i_dq[0]);
  return {core::inverse_clarke(core::inverse_park(i_dq, r)), core::inverse_clarke(core::inverse_park(turning, r))};
}

class PmsmPlant {
 public:
  PmsmPlant(int pole_pairs, Magnetics magnetics, MechanicsConfig mechanics) noexcept;

  /// Sets the initial state: current i_A at the given angle and speed.
  void reset(const core::Vec2& i_A, double theta_el_rad, double omega_el_rad_s, const PlantParameters& p) noexcept;

  /// Imposed speed (dynamometer mode); ignored in inertia mode.
  void set_speed(double omega_el_rad_s) noexcept;

  /// Starts a control period: takes the parameters, the step length and the load for its steps;
  /// every 32 periods re-derives the rotation from the angle (against round-off drift).
  void begin_period(const PlantParameters& p, double h_s, double load_torque_Nm) noexcept;

  /// One integration step (of the length given to begin_period) with the stator-frame voltage
  /// u_ab held over it.
  void step(const core::Vec2& u_ab_V) noexcept;

  /// Bridge off (sim/regime.hpp) for `steps` steps of the length given to begin_period: with no switch
  /// conducting, the freewheeling diodes return the current to the DC link within |i|·L/u_dc (microseconds:
  /// 8 µs from 20 A in 20 µH on 48 V, a tenth of a VESC control cycle), so the stator current is zero, the
  /// flux ψ(0), the torque zero; the rotor coasts against its load and friction (inertia mechanics) or turns
  /// at the imposed speed. Valid while the back EMF's line-to-line peak √3·|ω|·ψm stays below u_dc, where the
  /// diodes would start to rectify (the caller checks); the iron-loss branch is not modelled while off.
  void freewheel(int steps) noexcept;

  /// Edge-to-edge integration: the speed held over the period begun with begin_period(p, T, …) — the
  /// imposed one, or with inertia the speed half a period ahead at the last period's acceleration.
  [[nodiscard]] double period_speed() const noexcept { return state_.omega_el_rad_s + 0.5 * h_s_ * acceleration_el_; }
  /// Edge-to-edge integration: the state `dt_s` after the last one within the period, where the flux
  /// has reached ψ, at period_speed(). `i_flux_guess_A` starts the inversion of a flux map.
  /// Accumulates the torque's integral for end_period().
  void move_to(const core::Vec2& psi_Wb, const core::Vec2& i_flux_guess_A, double dt_s) noexcept;
  /// Ends an edge-integrated period: with inertia the speed changes by the period's mean torque, and
  /// the angle by the trapezoidal rule's (ω_k + ω_k+1)·T/2 less what period_speed() turned it.
  void end_period() noexcept;

  /// dψ/dt = u_dq − R_s·i_s − ω·J·ψ (J = [0 −1; 1 0]).
  [[nodiscard]] core::Vec2 derivative(const core::Vec2& psi, const core::Vec2& i, const core::Vec2& u_dq,
                                      double omega) const noexcept;
  /// Stator current i_s = i(ψ) + ω·J·ψ/R_fe from the magnetising current i(ψ).
  [[nodiscard]] core::Vec2 stator_current(const core::Vec2& psi, const core::Vec2& i_flux, double omega) const noexcept;

  [[nodiscard]] const PlantState& state() const noexcept { return state_; }
  [[nodiscard]] const PlantParameters& parameters() const noexcept { return parameters_; }
  /// i(ψ), the current the magnetics see (the stator current less the iron-loss branch's).
  [[nodiscard]] const core::Vec2& magnetising_current() const noexcept { return i_flux_A_; }
  [[nodiscard]] const core::Rotation& rotation() const noexcept { return rotation_; }
  /// Phase currents a, b, c [A].
  [[nodiscard]] core::Vec3 phase_currents() const noexcept;
  [[nodiscard]] const Magnetics& magnetics() const noexcept { return magnetics_; }
  [[nodiscard]] int pole_pairs() const noexcept { return pole_pairs_; }

 private:
  /// T_e = (3/2)·p·(ψ_d·i_q − ψ_q·i_d) of the present state.
  void update_torque() noexcept;
  /// dω_m/dt (mechanical) of the inertia at the electrical speed `omega` under the torque `torque_Nm`.
  [[nodiscard]] double acceleration(double torque_Nm, double omega) const noexcept;

  int pole_pairs_;
  Magnetics magnetics_;
  MechanicsConfig mechanics_;
  PlantState state_;
  core::Vec2 i_flux_A_ = core::Vec2::Zero();  ///< i(ψ), the current the magnetics see
  core::Rotation rotation_;
  PlantParameters parameters_;
  double h_s_ = 1e-6;
  double load_torque_Nm_ = 0.0;
  double torque_integral_Nms_ = 0.0;  ///< ∫T_e dt over the edge-integrated period so far
  double acceleration_el_ = 0.0;      ///< dω/dt over the last edge-integrated period
  core::Rotation step_rotation_;      ///< rotation by ω·h, fixed over a period
  unsigned periods_since_exact_rotation_ = 0;
};

}  // namespace rpem::sim
