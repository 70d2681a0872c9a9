#pragma once
// Field-oriented control at the PWM double-update rate (Section II, fig_FOCblockdiagram):
// speed PI → torque reference → MTPA (eq_refcurrents) → field weakening on the voltage ellipse →
// dq current PI with decoupling → inverse Park at the angle of the middle of the interval in which
// the command will act (ϑ + 1.5·ω·T: one period of computation delay plus half a period of PWM).
// The controller uses the nominal machine model, not the plant's true parameters.

#include "rpem/core/frames.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/core/types.hpp"

namespace rpem::sim {

struct FocConfig {
  double period_s = 125e-6;
  double current_bandwidth_Hz = 400.0;
  double speed_bandwidth_Hz = 5.0;
  double max_current_A = 0.0;    ///< |i| limit; 0: √2 × rated rms current
  double voltage_margin = 0.95;  ///< field weakening keeps the steady-state |u| below this × u_dc/√3
  bool field_weakening = true;
  bool speed_control = false;  ///< false: torque mode (the scenario commands torque); the initial mode
  double inertia_kgm2 = 0.01;  ///< for tuning the speed loop
};

struct FocInput {
  core::Vec3 i_abc_A = core::Vec3::Zero();  ///< measured phase currents
  double theta_el_rad = 0.0;                ///< measured angle
  double omega_el_rad_s = 0.0;              ///< measured speed
  double u_dc_V = 0.0;                      ///< measured DC link
  double torque_ref_Nm = 0.0;               ///< torque mode
  double speed_ref_el_rad_s = 0.0;          ///< speed mode
  bool speed_control = false;               ///< speed mode now (a scenario's regimes switch it; bumpless)
  /// Open loop and bridge off (sim/regime.hpp): the current reference in the controller's frame, the torque
  /// and speed loops, MTPA and field weakening bypassed.
  bool current_override = false;
  core::Vec2 current_ref_A = core::Vec2::Zero();
  /// The back-EMF feed-forward on q: off in open loop, where the back EMF's direction in the commanded frame
  /// is unknown (VESC's flux-linkage measurement runs with decoupling disabled).
  bool decouple = true;
};

struct FocOutput {
  core::Vec2 u_ab_V = core::Vec2::Zero();  ///< stator-frame command for the next interval
  core::Vec2 i_ref_A = core::Vec2::Zero();
  double torque_ref_Nm = 0.0;
  bool voltage_limited = false;
};

class FocController {
 public:
  FocController(const FocConfig& config, const core::MachineSi& nominal) noexcept;
  [[nodiscard]] FocOutput step(const FocInput& in) noexcept;
  void reset() noexcept;
  /// Bridge off: presets the current PI's integrators so that, at zero current, the command is u_dq_V (the
  /// back EMF the drive measures), as the firmware sets vd_int, vq_int to its tracked v_d, v_q while undriven
  /// (mcpwm_foc.c): re-engaging the bridge then applies the back EMF, not a stale voltage.
  void preset(const core::Vec2& u_dq_V, double omega_el_rad_s) noexcept;

 private:
  /// Field weakening on the nominal model's voltage ellipse, then the current limit.
  [[nodiscard]] core::Vec2 field_weaken(core::Vec2 i_ref, double torque_Nm, double omega, double u_limit) const noexcept;

  FocConfig config_;
  core::MachineSi nominal_;
  core::PerUnitBase base_;
  core::MachinePu nominal_pu_;
  double i_max_A_;
  core::Vec2 integral_V_ = core::Vec2::Zero();
  double speed_integral_Nm_ = 0.0;
  double last_torque_ref_Nm_ = 0.0;  ///< the torque reference of the last step (0 when overridden)
  bool was_speed_control_ = false;   ///< speed mode in the last step
  double mtpa_torque_Nm_ = 0.0;      ///< torque of the cached MTPA references
  core::Vec2 mtpa_i_A_ = core::Vec2::Zero();
  core::RotationTracker rotation_;  ///< at the measured angle
};

}  // namespace rpem::sim
