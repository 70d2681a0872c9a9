#include "rpem/analysis/thermal/thermal_topology.hpp"

#include <algorithm>

namespace rpem::analysis {

io::ThermalConfig default_topology(const io::ThermalConfig& laws, const ThermalRecord& r, int nodes) {
  io::ThermalConfig c = laws;
  core::ThermalNetwork& n = c.fusion.filter.network;
  // Scales from the record: the mean copper loss at the reference resistance and a temperature rise.
  double i2 = 0.0, iron = 0.0, magnet_eddy = 0.0, i2_max = 0.0;
  for (const core::ThermalStepData& s : r.steps) {
    i2 += s.load.current_sq_A2;
    i2_max = std::max(i2_max, s.load.current_sq_A2);
    iron += s.load.basis[static_cast<std::size_t>(core::LossForm::kIronEddy)];
    magnet_eddy += s.load.basis[static_cast<std::size_t>(core::LossForm::kMagnetEddy)];
  }
  const double count = std::max<double>(1.0, static_cast<double>(r.steps.size()));
  const double copper_W = std::max(1.5 * n.copper.value_ref * i2 / count, 1.0);
  const double iron_basis = std::max(iron / count, 1e-3);
  const double magnet_basis = std::max(magnet_eddy / count, 1e-3);
  const double rise_K = 60.0;  // a machine near its rating
  // The winding's conductance: the mean copper loss over a typical rise, at least three times the copper loss's
  // own growth with temperature at the largest current ((3/2)·R_ref·α·i²_max: below it the network runs away).
  const double feedback_W_per_K = 1.5 * n.copper.value_ref * n.copper.coeff_per_K * i2_max;
  const double g_W_per_K = std::max(copper_W / rise_K, 3.0 * feedback_W_per_K);
  n.nodes = nodes;
  n.between_W_per_K.setZero();
  n.between_at_base_speed_W_per_K.setZero();
  n.loss_at_base_W.setZero();
  n.to_coolant_W_per_K.setZero();
  n.to_coolant_at_base_speed_W_per_K.setZero();
  n.capacitance_J_per_K.setOnes();
  c.node_names = {};
  c.fusion.filter.process_noise_K2_per_s.setZero();
  const int eddy = static_cast<int>(core::LossForm::kIronEddy), hyst = static_cast<int>(core::LossForm::kIronHysteresis);
  const int magnet = static_cast<int>(core::LossForm::kMagnetEddy);
  if (nodes == 2) {
    // winding (with the stator), magnet (with the rotor)
    c.node_names[0] = "winding", c.node_names[1] = "magnet";
    n.winding = 0, n.magnet = 1;
    n.to_coolant_W_per_K << g_W_per_K, 0.2 * g_W_per_K, 0, 0;
    n.to_coolant_at_base_speed_W_per_K[1] = 0.2 * g_W_per_K;  // the rotor's convection (eq. 14.1b)
    n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 0.15 * g_W_per_K;
    n.between_at_base_speed_W_per_K(0, 1) = n.between_at_base_speed_W_per_K(1, 0) = 0.15 * g_W_per_K;  // the air gap
    n.capacitance_J_per_K << 300.0 * g_W_per_K, 1500.0 * 0.5 * g_W_per_K, 1, 1;
    n.loss_at_base_W(hyst, 0) = n.loss_at_base_W(eddy, 0) = 0.1 * copper_W / iron_basis;
    n.loss_at_base_W(eddy, 1) = 0.05 * copper_W / iron_basis;
    n.loss_at_base_W(magnet, 1) = 0.05 * copper_W / magnet_basis;
  } else {
    // winding, stator iron (teeth and yoke, on the cooling jacket), magnet (with the rotor)
    c.node_names[0] = "winding", c.node_names[1] = "stator_iron", c.node_names[2] = "magnet";
    n.winding = 0, n.magnet = 2;
    n.to_coolant_W_per_K << 0.1 * g_W_per_K, 2.0 * g_W_per_K, 0.1 * g_W_per_K, 0;
    n.to_coolant_at_base_speed_W_per_K[2] = 0.1 * g_W_per_K;  // the rotor's convection (eq. 14.1b)
    n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 1.5 * g_W_per_K;
    n.between_W_per_K(1, 2) = n.between_W_per_K(2, 1) = 0.15 * g_W_per_K;
    n.between_at_base_speed_W_per_K(1, 2) = n.between_at_base_speed_W_per_K(2, 1) = 0.15 * g_W_per_K;  // the air gap
    n.capacitance_J_per_K << 100.0 * g_W_per_K, 600.0 * g_W_per_K, 1500.0 * 0.4 * g_W_per_K, 1;
    n.loss_at_base_W(hyst, 1) = n.loss_at_base_W(eddy, 1) = 0.1 * copper_W / iron_basis;
    n.loss_at_base_W(eddy, 2) = 0.05 * copper_W / iron_basis;
    n.loss_at_base_W(magnet, 2) = 0.05 * copper_W / magnet_basis;
  }
  return c;
}

}  // namespace rpem::analysis
