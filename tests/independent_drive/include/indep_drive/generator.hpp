#pragma once
// The independent drive-log generator: a Case in, rows and the truth out (README "API").
#include <vector>

#include "indep_drive/averager.hpp"
#include "indep_drive/case.hpp"
#include "indep_drive/frames.hpp"
#include "indep_drive/truth.hpp"

namespace indep {

/// One row of the drive log (docs/drive-log.md): what the drive measured at t and the command it issued then.
struct LogRow {
  double t_s = 0, theta_el_rad = 0, omega_el_rad_s = 0, u_dc_V = 0;
  std::array<double, 3> u_abc_V{}, i_abc_A{};
  double T_winding_C = 0, T_magnet_C = 0, torque_cmd_Nm = 0;
};

/// The true plant per control period: state at t, applied voltage averaged over [t, t + T_c).
struct PlantRow {
  double t_s = 0, theta_el_rad = 0, omega_el_rad_s = 0;
  Vec2 i_A;             // true terminal current, true rotor frame
  Vec2 u_applied_V;     // applied voltage averaged over the period, true rotor frame
  Vec2 u_applied_ab_V;  // the same in the stator frame (α, β)
  double psi_m_Wb = 0, r_s_Ohm = 0, torque_Nm = 0, T_winding_C = 0, T_magnet_C = 0;
};

struct Result {
  Case resolved;  // the case with every default filled in
  std::vector<LogRow> log;
  std::vector<PlantRow> plant;
  std::vector<AveragedRow> averaged;
  Truth truth;
};

/// Runs the case. Throws std::invalid_argument (bad case) or std::runtime_error (a map that cannot be used).
Result generate(const Case& c);

}  // namespace indep
