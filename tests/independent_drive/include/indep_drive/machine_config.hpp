#pragma once
// The machine section of an rpem configuration YAML (docs/configuration.md, `machine`), read directly with
// yaml-cpp: the values the diagnosis is told, from which the generator draws its true machine.
#include <stdexcept>
#include <string>

namespace indep {

struct MachineParams {
  double psi_m_Wb = 0.0;
  double r_s_Ohm = 0.0;
  double l_d_H = 0.0;
  double l_q_H = 0.0;
  int pole_pairs = 0;
};

struct RatedData {
  double voltage_ll_rms_V = 0.0;
  double current_rms_A = 0.0;
  double speed_rpm = 0.0;
  double power_W = 0.0;  // 0 when the configuration does not give it
};

struct MachineConfig {
  MachineParams params;
  RatedData rated;
  std::string source;  // the file it came from ("" when built in code)

  /// Peak rated phase current √2·I_n [A].
  [[nodiscard]] double rated_peak_current_A() const;
  /// Rated electrical speed ω_n = 2π·N_n/60·p [rad/s].
  [[nodiscard]] double rated_omega_el_rad_s() const;
  /// Torque base 1.5·p·ψm·√2·I_n [Nm] (the profile's torque unit; configured ψm).
  [[nodiscard]] double torque_base_Nm() const;
  /// Reference power: rated.power_W, else √3·U_n·I_n [W].
  [[nodiscard]] double reference_power_W() const;
};

/// A configuration that cannot be used; the message names file, line and key.
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Reads `machine:` of a configuration file. Throws ConfigError naming `file:line: machine.key: reason`.
MachineConfig read_machine_config(const std::string& path);

}  // namespace indep
