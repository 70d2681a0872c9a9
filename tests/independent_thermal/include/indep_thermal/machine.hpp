#pragma once
// The machine section of an rpem configuration YAML (`machine:`), read with yaml-cpp: the configured
// electrical parameters and the name plate from which the plant's nominal thermal parameters are sized.
#include <string>

namespace indep_thermal {

struct Machine {
  double voltage_ll_rms_V = 0.0;  // U_n
  double current_rms_A = 0.0;     // I_n
  double speed_rpm = 0.0;         // N_n (mechanical)
  int pole_pairs = 0;             // p
  double power_W = 0.0;           // P_n, 0 when not given
  double torque_Nm = 0.0;         // T_n, 0 when not given
  double r_s_Ohm = 0.0;
  double psi_m_Wb = 0.0;
  double l_d_H = 0.0;
  double l_q_H = 0.0;
  std::string source;  // the file it came from

  /// √2·I_n [A].
  [[nodiscard]] double peak_current_A() const;
  /// √2·U_n/√3, the peak phase voltage [V].
  [[nodiscard]] double peak_voltage_V() const;
  /// 2π·N_n/60 [rad/s].
  [[nodiscard]] double omega_mech_rated_rad_s() const;
  /// p·2π·N_n/60 [rad/s].
  [[nodiscard]] double omega_el_rated_rad_s() const;
  /// Rated torque: torque_Nm, else power_W/ω_n, else 0.85·√3·U_n·I_n/ω_n (power factor times efficiency
  /// 0.85 assumed) [Nm].
  [[nodiscard]] double rated_torque_Nm() const;
  /// Rated shaft power T_n·ω_n [W].
  [[nodiscard]] double rated_power_W() const;
};

/// Reads `machine:` of a configuration file; throws ConfigError naming `file:line: machine.key: reason`.
Machine read_machine(const std::string& path);

}  // namespace indep_thermal
