#pragma once
// IPMSM plant in the rotor frame, SI, flux linkages as states (so flux maps with cross-saturation
// fit without differential inductances):
//   dψ_d/dt = u_d − R_s·i_d + ω·ψ_q,   dψ_q/dt = u_q − R_s·i_q − ω·ψ_d
//   T_e = (3/2)·p·(ψ_d·i_q − ψ_q·i_d)
// With iron loss (R_fe > 0) the induced voltage e = ω·J·ψ drives a parallel current e/R_fe that the
// stator current also supplies: i_s = i(ψ) + ω·J·ψ/R_fe.
// Integrated with Heun's method (second order); the stator-frame voltage is constant over each step
// and rotates into the rotor frame at both ends. Mechanics: imposed speed (dynamometer, as on the
// bench) or J·dω_m/dt = T_e − T_load − B·ω_m.

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

  [[nodiscard]] const PlantState& state() const noexcept { return state_; }
  [[nodiscard]] const core::Rotation& rotation() const noexcept { return rotation_; }
  /// Phase currents a, b, c [A].
  [[nodiscard]] core::Vec3 phase_currents() const noexcept;
  [[nodiscard]] const Magnetics& magnetics() const noexcept { return magnetics_; }
  [[nodiscard]] int pole_pairs() const noexcept { return pole_pairs_; }

 private:
  [[nodiscard]] core::Vec2 derivative(const core::Vec2& psi, const core::Vec2& i, const core::Vec2& u_dq,
                                      double omega) const noexcept;
  [[nodiscard]] core::Vec2 stator_current(const core::Vec2& psi, const core::Vec2& i_flux,
                                          double omega) const noexcept;

  int pole_pairs_;
  Magnetics magnetics_;
  MechanicsConfig mechanics_;
  PlantState state_;
  core::Vec2 i_flux_A_ = core::Vec2::Zero();  ///< i(ψ), the current the magnetics see
  core::Rotation rotation_;
  PlantParameters parameters_;
  double h_s_ = 1e-6;
  double load_torque_Nm_ = 0.0;
  core::Rotation step_rotation_;  ///< rotation by ω·h, fixed over a period
  unsigned periods_since_exact_rotation_ = 0;
};

}  // namespace rpem::sim
