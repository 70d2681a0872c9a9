#include "indep_thermal/network.hpp"

#include "indep_thermal/convection.hpp"

namespace indep_thermal {

Eigen::Matrix3d Conductances::matrix() const {
  Eigen::Matrix3d g = Eigen::Matrix3d::Zero();
  auto link = [&g](int a, int b, double value) {
    g(a, a) += value;
    g(b, b) += value;
    g(a, b) -= value;
    g(b, a) -= value;
  };
  link(kWinding, kIron, winding_iron);
  link(kRotor, kIron, airgap);
  link(kWinding, kRotor, winding_rotor);
  g.diagonal() += to_coolant();
  return g;
}

Eigen::Vector3d Conductances::to_coolant() const { return {winding_coolant, iron_coolant, rotor_coolant}; }

Conductances conductances(const Parameters& p, double omega_mech_rad_s) {
  const EndSpaceConductances e = endspace_conductances(p, omega_mech_rad_s);
  Conductances g;
  g.winding_iron = p.g_winding_iron_W_K;
  g.iron_coolant = p.g_iron_coolant_W_K;
  g.airgap = airgap_conductance_W_K(p, omega_mech_rad_s);
  g.winding_rotor = e.winding_rotor;
  g.winding_coolant = e.winding_coolant;
  g.rotor_coolant = e.rotor_coolant + p.g_shaft_W_K;
  return g;
}

Eigen::Vector3d capacities(const Parameters& p) { return {p.c_winding_J_K, p.c_iron_J_K, p.c_rotor_J_K}; }

}  // namespace indep_thermal
