#pragma once
// The one place that converts between SI and per-unit (pu).
//
// Base choice (docs/per-unit.md): amplitude-invariant peak phase quantities.
//   U_b = √2·U_n/√3 (U_n line-to-line rms), I_b = √2·I_n (I_n rms), ω_b = 2π·p·N_n/60,
//   ψ_b = U_b/ω_b, Z_b = U_b/I_b, L_b = Z_b/ω_b, T_b = (3/2)·p·ψ_b·I_b, ω_mech,b = ω_b/p.
// With this base the rotor-frame machine equations (eq:1, Eq_FullOrderModel) hold in pu with
// torque τ = ψm·i_q + (x_d − x_q)·i_d·i_q, and tab_machineData's rated torque 32.6 Nm equals T_b.
// Time is not normalised: t stays in seconds and ω_n = ω_b appears explicitly in the model.

#include "rpem/core/types.hpp"

namespace rpem::core {

/// Name-plate data (tab_machineData) from which the base is built.
struct RatedData {
  double voltage_ll_rms_V = 0.0;  ///< rated line-to-line rms voltage U_n
  double current_rms_A = 0.0;     ///< rated phase rms current I_n
  double speed_rpm = 0.0;         ///< rated mechanical speed N_n
  int pole_pairs = 0;             ///< p
};

struct PerUnitBase {
  double voltage_V = 0.0;         ///< U_b, peak phase voltage
  double current_A = 0.0;         ///< I_b, peak phase current
  double omega_el_rad_s = 0.0;    ///< ω_b = ω_n, electrical
  double omega_mech_rad_s = 0.0;  ///< ω_b / p
  double flux_Wb = 0.0;           ///< ψ_b
  double impedance_Ohm = 0.0;     ///< Z_b
  double inductance_H = 0.0;      ///< L_b
  double torque_Nm = 0.0;         ///< T_b
  int pole_pairs = 0;

  /// Builds the base from name-plate data; all fields are finite and positive for valid ratings.
  [[nodiscard]] static PerUnitBase from_rated(const RatedData& rated) noexcept;

  // SI → pu
  [[nodiscard]] constexpr double voltage_pu(double v_V) const noexcept { return v_V / voltage_V; }
  [[nodiscard]] constexpr double current_pu(double i_A) const noexcept { return i_A / current_A; }
  [[nodiscard]] constexpr double speed_pu(double omega_el_rad_s_in) const noexcept {
    return omega_el_rad_s_in / omega_el_rad_s;
  }
  [[nodiscard]] constexpr double flux_pu(double psi_Wb) const noexcept { return psi_Wb / flux_Wb; }
  [[nodiscard]] constexpr double resistance_pu(double r_Ohm) const noexcept { return r_Ohm / impedance_Ohm; }
  [[nodiscard]] constexpr double inductance_pu(double l_H) const noexcept { return l_H / inductance_H; }
  [[nodiscard]] constexpr double torque_pu(double t_Nm) const noexcept { return t_Nm / torque_Nm; }
  [[nodiscard]] double mech_speed_rpm_to_pu(double n_rpm) const noexcept;

  // pu → SI
  [[nodiscard]] constexpr double voltage_V_of(double v_pu) const noexcept { return v_pu * voltage_V; }
  [[nodiscard]] constexpr double current_A_of(double i_pu) const noexcept { return i_pu * current_A; }
  [[nodiscard]] constexpr double omega_el_rad_s_of(double n_pu) const noexcept { return n_pu * omega_el_rad_s; }
  [[nodiscard]] constexpr double flux_Wb_of(double psi_pu) const noexcept { return psi_pu * flux_Wb; }
  [[nodiscard]] constexpr double resistance_Ohm_of(double r_pu) const noexcept { return r_pu * impedance_Ohm; }
  [[nodiscard]] constexpr double inductance_H_of(double x_pu) const noexcept { return x_pu * inductance_H; }
  [[nodiscard]] constexpr double torque_Nm_of(double t_pu) const noexcept { return t_pu * torque_Nm; }
  [[nodiscard]] double mech_speed_rpm_of(double n_pu) const noexcept;
};

}  // namespace rpem::core
