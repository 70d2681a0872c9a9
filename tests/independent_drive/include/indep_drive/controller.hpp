#pragma once
// The drive's field-oriented current control, on the configured (not the true) machine (README "Controller"):
// torque → currents by exact MTPA, PI per axis with the plant zero cancelled, decoupling feed-forward from
// the references, back-calculation anti-windup at the modulation's linear limit, and the angle advanced by
// a fraction of a period for the zero-order hold.
#include <array>

#include "indep_drive/frames.hpp"
#include "indep_drive/inverter.hpp"
#include "indep_drive/machine_config.hpp"

namespace indep {

/// Least current magnitude for torque T on the machine m (MTPA), capped at i_max:
///   i_d(I) = (ψm − √(ψm² + 8·ΔL²·I²)) / (4·ΔL),  i_q = sign(T)·√(I² − i_d²),  ΔL = L_q − L_d
///   T(I) = 1.5·p·(ψm·i_q + (L_d − L_q)·i_d·i_q), solved for I by bisection.
Vec2 mtpa_current(double torque_Nm, const MachineParams& m, double i_max_A);

struct ControllerConfig {
  MachineParams model;              // what the drive believes
  double period_s = 125e-6;         // T_c
  double bandwidth_rad_s = 1257.0;  // ω_bw: K_p = L·ω_bw, K_i = R·ω_bw
  double current_limit_A = 10.0;
  double angle_advance_periods = 0.5;
  double voltage_margin = 0.98;  // fraction of the linear range used
  Modulation modulation = Modulation::space_vector;
};

struct ControllerOutput {
  Vec2 i_ref_A;                     // rotor frame of the measured angle
  Vec2 u_dq_V;                      // command, rotor frame of the measured angle
  std::array<double, 3> u_abc_V{};  // command, stator frame (zero sum): what the log records
  std::array<double, 3> duty{};     // issued leg duty cycles
  bool saturated = false;
};

class CurrentController {
 public:
  explicit CurrentController(const ControllerConfig& config);
  ControllerOutput step(const std::array<double, 3>& i_abc_meas_A, double theta_meas_rad, double omega_meas_rad_s,
                        double u_dc_meas_V, double torque_cmd_Nm, double i_d_inject_A);

 private:
  ControllerConfig c_;
  Vec2 integral_V_;
};

}  // namespace indep
