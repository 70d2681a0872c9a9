#pragma once
// Losses per node at an operating point (README.md, "Losses"), f = |ω_el|/2π, x = f/f_n, B = |ψ|/ψm_ref with
// ψ = (ψm(T_r) + L_d·i_d, L_q·i_q) the stator flux linkage, n = |ω_m|/ω_n, j = |i|/Î_n:
//   winding  P_cu = 1.5·R_dc(T_w)·(1 + k_ac·x²)·(i_d² + i_q²)
//   iron     P_fe,s = P_s,n·(h·x·B^β + (1 − h − e)·x²·B² + e·x^1.5·B^1.5)      (Bertotti's separation)
//   rotor    P_fe,r = P_r,n·(h_r·x·B^β + (1 − h_r)·x²·B²)
//            P_mag  = P_m,n·x²·j²                                            (armature-reaction harmonics)
//            P_mech = P_b,n·(b·n + (1 − b)·n³)                                (bearings, windage)
#include "indep_thermal/parameters.hpp"

namespace indep_thermal {

struct OperatingPoint {
  double omega_el_rad_s = 0.0;
  double i_d_A = 0.0;
  double i_q_A = 0.0;
};

struct Losses {
  double copper = 0.0;
  double stator_hysteresis = 0.0;
  double stator_eddy = 0.0;
  double stator_excess = 0.0;
  double rotor_iron = 0.0;
  double magnet = 0.0;
  double mechanical = 0.0;
  double flux_rel = 0.0;  // B = |ψ|/ψm_ref

  [[nodiscard]] double winding() const { return copper; }
  [[nodiscard]] double iron() const { return stator_hysteresis + stator_eddy + stator_excess; }
  [[nodiscard]] double rotor() const { return rotor_iron + magnet + mechanical; }
  [[nodiscard]] double total() const { return winding() + iron() + rotor(); }
};

/// Losses at an operating point with winding temperature T_w and magnet (rotor) temperature T_r [W].
Losses compute_losses(const Parameters& p, const OperatingPoint& op, double t_winding_C, double t_rotor_C);

}  // namespace indep_thermal
