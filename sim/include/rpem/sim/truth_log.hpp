#pragma once
// The truth CSV beside a simulated drive log: t and the plant's true parameters and state (SI).
//   t,psi_m,r_s,l_d,l_q,T_winding,T_magnet,omega_el,theta_el,torque,i_d,i_q

#include <fstream>
#include <string>

#include "rpem/sim/drive_simulator.hpp"

namespace rpem::sim {

class TruthLogWriter {
 public:
  explicit TruthLogWriter(const std::string& path);
  void write(const TruthRow& row);

 private:
  std::ofstream out_;
  std::string line_;
};

}  // namespace rpem::sim
