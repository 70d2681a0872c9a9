#pragma once
// The electrical side, in the rotor frame and in steady state (rows seconds apart: the electrical transients,
// milliseconds long, are over). The drive chooses the currents with the configured machine; the voltages
// follow from the true machine at this instant's temperatures (README.md, "Electrical side"):
//   u_d = R·i_d − ω·L_q·i_q,   u_q = R·i_q + ω·(L_d·i_d + ψm(T_r)),   R = R_dc(T_w)·(1 + k_ac·(f/f_n)²).
#include "indep_thermal/losses.hpp"
#include "indep_thermal/machine.hpp"
#include "indep_thermal/parameters.hpp"

namespace indep_thermal {

struct DqVoltage {
  double u_d_V = 0.0;
  double u_q_V = 0.0;
};

/// Steady-state dq voltage of the true machine at T_w, T_r.
DqVoltage steady_state_voltage(const Parameters& p, const OperatingPoint& op, double t_winding_C, double t_rotor_C);

/// What the profile asks of the drive at one instant.
struct Demand {
  double speed_rpm = 0.0;
  double i_q_A = 0.0;
  double i_d_A = 0.0;
  bool i_d_given = false;  // else the drive chooses i_d (MTPA, then field weakening)
};

/// The currents the drive applies: i_q derated linearly between drive.derate_start_C and derate_end_C of the
/// winding sensor; i_d given, or MTPA of the configured machine raised (field weakening) until the configured
/// machine's steady-state |u| meets drive.voltage_limit_rel·Û_n; |i| limited to drive.current_limit_rel·Î_n by
/// reducing i_q.
OperatingPoint drive_currents(const Machine& configured, const Parameters& p, const Demand& demand,
                              double t_winding_sensor_C);

/// MTPA d current for a q current: the root of ΔL·i_d² − ψm·i_d − ΔL·i_q² = 0 with i_d ≤ 0, ΔL = L_q − L_d
/// (0 when ΔL ≤ 0).
double mtpa_i_d_A(double psi_m_Wb, double l_d_H, double l_q_H, double i_q_A);

}  // namespace indep_thermal
