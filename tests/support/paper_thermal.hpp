#pragma once
// A three-node thermal network for the paper's machine (winding, iron, magnet) and its fusion settings, for
// tests of the real-time path (core's and the daemon loop's allocation tests, the filter's bench). Magnitudes of
// a 2 kW machine; the filter's gate tight (resets happen) and its observer quick (observations happen within
// a test's seconds).

#include "rpem/core/thermal_fusion.hpp"
#include "support/paper_machine.hpp"

namespace rpem::test {

inline core::ThermalFusionConfig paper_thermal_fusion() {
  core::ThermalFusionConfig c;
  core::ThermalNetwork& n = c.filter.network;
  n.nodes = 3;
  n.winding = 0, n.magnet = 2;
  n.capacitance_J_per_K << 3000.0, 12000.0, 7000.0, 1.0;
  n.to_coolant_W_per_K << 2.0, 90.0, 4.0, 0.0;
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 40.0;
  n.between_W_per_K(1, 2) = n.between_W_per_K(2, 1) = 12.0;
  n.copper = {0.00393, 20.0, 2.25};
  n.base = core::loss_base_of(paper_base(), paper_machine_si());
  n.loss_at_base_W(static_cast<int>(core::LossForm::kIronEddy), 1) = 100.0;
  n.loss_at_base_W(static_cast<int>(core::LossForm::kMagnetEddy), 2) = 20.0;
  c.filter.loss_rel_sigma.setConstant(0.5);
  c.filter.process_noise_K2_per_s.setConstant(1e-3);
  c.filter.disturbance_W2_per_s.setConstant(1.0);
  c.filter.gate_sigma = 1.0;  // tight: gate resets happen
  c.magnet_law = {-0.0012, 20.0, 1.14};
  c.observer.period_s = 0.01;
  c.observer.settle_time_constants = 1.0;
  c.winding_sensor_sigma_K = 1.0;
  return c;
}

}  // namespace rpem::test
