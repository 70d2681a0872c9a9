#pragma once
// The motor on its shaft (README "Plant"): stator flux linkage in the stationary frame, the rotor angle and the
// shaft speed, integrated together with classical RK4 over intervals in which the legs' average voltages are
// held (the PWM periods' halves between two timer update events).
//
//   ψ_αβ = e^{jθ}·(L_d·i_d + ψm, L_q·i_q)          (i from ψ: i_d = (ψ_d − ψm)/L_d, i_q = ψ_q/L_q, ψ_dq = e^{−jθ}ψ_αβ)
//   dψ_αβ/dt = v_αβ − R_s·i_αβ,  v_αβ = Clarke(v_x − ΔV·σ(i_x/i_band)),  σ(x) = x/√(1 + x²),  ΔV = t_dead·f_sw·V_dc
//   T_e = 1.5·p·(ψ_α·i_β − ψ_β·i_α)
//   J·dω_m/dt = T_e − T_c·σ(ω_m/ω_ε) − b·ω_m − k·ω_m·|ω_m| − T_ext,   dθ/dt = p·ω_m
//
// With the bridge off the phases are open: i = 0, ψ_αβ = ψm·e^{jθ}, and only the shaft is integrated.
#include <array>

#include "indep_drive/frames.hpp"

namespace indep::vesc {

using indep::Vec2;

struct PlantParams {
  double r_s_Ohm = 0.0;
  double psi_m_Wb = 0.0;
  double l_d_H = 0.0, l_q_H = 0.0;
  int pole_pairs = 1;
  double inertia_kgm2 = 0.0;
  double coulomb_Nm = 0.0, coulomb_band_rad_s = 0.5, viscous_Nm_s = 0.0, drag_Nm_s2 = 0.0, external_Nm = 0.0;
  double t_dead_s = 0.0;     // per-leg dead time
  double f_sw_Hz = 12500.0;  // switching frequency
  double dead_band_A = 0.5;  // the current over which the dead-time error changes sign
};

struct PlantState {
  Vec2 psi_ab_Wb;
  double theta_el_rad = 0.0;   // unwrapped
  double omega_m_rad_s = 0.0;  // shaft
};

/// What one held interval did: means and integrals over it (RK4's weights 1, 2, 2, 1: Simpson's rule).
struct IntervalResult {
  Vec2 v_dq_mean_V;             // the applied voltage in the true rotor frame, mean over the interval
  Vec2 i_dq_mean_A;             // the current in the true rotor frame, mean over the interval
  double energy_in_J = 0.0;     // ∫1.5·v·i dt at the terminals (after the dead-time error)
  double energy_cu_J = 0.0;     // ∫1.5·R_s·|i|² dt
  double energy_load_J = 0.0;   // ∫T_load·ω_m dt (friction, drag, external)
  double energy_shaft_J = 0.0;  // ∫T_e·ω_m dt
};

class Plant {
 public:
  explicit Plant(const PlantParams& p);

  [[nodiscard]] const PlantParams& params() const { return p_; }
  /// The temperature-dependent values, changed between intervals (thermal model).
  void set_r_s(double r_s_Ohm) { p_.r_s_Ohm = r_s_Ohm; }
  void set_psi_m(double psi_m_Wb);
  void set_external_torque(double t_Nm) { p_.external_Nm = t_Nm; }
  void set_coulomb(double t_Nm) { p_.coulomb_Nm = t_Nm; }
  void set_viscous(double b_Nm_s) { p_.viscous_Nm_s = b_Nm_s; }

  [[nodiscard]] Vec2 current_dq(const PlantState& x) const;
  [[nodiscard]] Vec2 current_ab(const PlantState& x) const;
  [[nodiscard]] double torque_Nm(const PlantState& x) const;
  [[nodiscard]] double load_torque_Nm(double omega_m_rad_s) const;
  /// Magnetic energy stored in the inductances, 1.5·(½L_d·i_d² + ½L_q·i_q²) [J].
  [[nodiscard]] double magnetic_energy_J(const PlantState& x) const;
  [[nodiscard]] double kinetic_energy_J(const PlantState& x) const;

  /// Integrates h with the legs held at `leg_V` (average over the interval, against DC−) from a link at v_dc_V.
  IntervalResult step_on(PlantState& x, double h, const std::array<double, 3>& leg_V, double v_dc_V) const;
  /// Integrates h with the bridge off (i = 0).
  IntervalResult step_off(PlantState& x, double h) const;
  /// Opens the phases: the current is gone (diodes return it to the link within microseconds).
  void open_phases(PlantState& x) const;

 private:
  struct Rate {
    Vec2 dpsi;
    double dtheta = 0.0, domega = 0.0;
    Vec2 v_dq, i_dq;
    double p_in = 0.0, p_cu = 0.0, p_load = 0.0, p_shaft = 0.0;
  };
  [[nodiscard]] Rate rate_on(const PlantState& x, const std::array<double, 3>& leg_V, double dead_V) const;
  [[nodiscard]] Rate rate_off(const PlantState& x) const;
  template <class F>
  IntervalResult rk4(PlantState& x, double h, const F& rate) const;

  PlantParams p_;
};

}  // namespace indep::vesc
