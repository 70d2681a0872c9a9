#include "indep_thermal/convection.hpp"

#include <algorithm>
#include <cmath>

#include "indep_thermal/pi.hpp"

namespace indep_thermal {

double taylor_number(const Parameters& p, double omega_mech_rad_s) {
  const double r_r = 0.5 * p.rotor_diameter_m;
  const double reynolds = std::abs(omega_mech_rad_s) * r_r * p.airgap_m / p.air_viscosity_m2_s;
  return reynolds * std::sqrt(p.airgap_m / r_r);
}

double airgap_nusselt(double taylor, double prandtl) {
  const double pr = std::pow(prandtl, 0.27);
  const double vortex = 0.202 * std::pow(taylor, 0.63) * pr;
  const double turbulent = 0.386 * std::sqrt(taylor) * pr;
  return std::max(2.0, std::min(vortex, turbulent));
}

double airgap_conductance_W_K(const Parameters& p, double omega_mech_rad_s) {
  const double nu = airgap_nusselt(taylor_number(p, omega_mech_rad_s), p.air_prandtl);
  const double h = nu * p.air_conductivity_W_mK / (2.0 * p.airgap_m);
  return h * kPi * p.rotor_diameter_m * p.active_length_m;
}

double endspace_h_W_m2K(const Parameters& p, double v_m_s) {
  return p.endspace_k1_W_m2K * (1.0 + p.endspace_k2 * std::pow(std::abs(v_m_s), p.endspace_k3));
}

EndSpaceAreas endspace_areas(const Parameters& p) {
  EndSpaceAreas a;
  a.winding_m2 = 2.0 * kPi * (p.rotor_diameter_m + p.stator_outer_diameter_m) * p.endwinding_overhang_m;
  a.rotor_m2 = 2.0 * kPi / 4.0 * p.rotor_diameter_m * p.rotor_diameter_m;
  a.caps_m2 = 2.0 * kPi / 4.0 * p.stator_outer_diameter_m * p.stator_outer_diameter_m;
  return a;
}

EndSpaceConductances endspace_conductances(const Parameters& p, double omega_mech_rad_s) {
  const double h = endspace_h_W_m2K(p, omega_mech_rad_s * 0.5 * p.rotor_diameter_m);
  const EndSpaceAreas a = endspace_areas(p);
  // Star with centre the end-space air: g_i = h·A_i. Eliminating the (massless) centre gives the delta
  // g_ij = g_i·g_j/Σg, the same heat flows for any node temperatures.
  const double sum = a.winding_m2 + a.rotor_m2 + a.caps_m2;
  EndSpaceConductances g;
  g.winding_rotor = h * a.winding_m2 * a.rotor_m2 / sum;
  g.winding_coolant = h * a.winding_m2 * a.caps_m2 / sum;
  g.rotor_coolant = h * a.rotor_m2 * a.caps_m2 / sum;
  return g;
}

}  // namespace indep_thermal
