#pragma once
// CSV output (README "Outputs"): the drive log per docs/drive-log.md, the averaged rotor-frame log and the
// true plant state. Numbers in the shortest form that reads back exactly (std::to_chars).
#include <string>
#include <vector>

#include "indep_drive/generator.hpp"

namespace indep {

inline constexpr const char* kLogHeader = "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c,T_winding,T_magnet,torque_cmd";
inline constexpr const char* kAveragedHeader = "t,t_start,i_d,i_q,u_d,u_q,omega_el,u_dc,T_winding,T_magnet";
inline constexpr const char* kPlantHeader =
    "t,theta_el,omega_el,i_d,i_q,u_d_applied,u_q_applied,u_alpha_applied,u_beta_applied,psi_m,r_s,torque,T_winding,T_magnet";

std::string log_csv(const std::vector<LogRow>& rows);
std::string averaged_csv(const std::vector<AveragedRow>& rows);
std::string plant_csv(const std::vector<PlantRow>& rows);

/// Writes text to path; throws std::runtime_error naming the path.
void write_file(const std::string& path, const std::string& text);

}  // namespace indep
