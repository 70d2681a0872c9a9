#pragma once
// The paper's machine (tab_machineData) as the simulator's plant parameters, for sim tests.

#include "rpem/sim/plant.hpp"
#include "support/paper_machine.hpp"

namespace rpem::test {

inline sim::PlantParameters paper_plant_parameters() {
  const auto m = paper_machine_si();
  sim::PlantParameters p;
  p.r_s_Ohm = m.r_s_Ohm;
  p.psi_m_Wb = m.psi_m_Wb;
  p.l_d_H = m.l_d_H;
  p.l_q_H = m.l_q_H;
  return p;
}

}  // namespace rpem::test
