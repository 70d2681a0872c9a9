#include "machine_option.hpp"

#include <cstdio>

#include "rpem/core/per_unit.hpp"

namespace rpem::tools {

io::MachineConfig machine_config_or_builtin(const std::string& path, const char* tool) {
  if (!path.empty()) return io::load_machine_config(path);
  io::MachineConfig c = io::builtin_paper_config();
  const core::PerUnitBase base = core::PerUnitBase::from_rated(c.machine.rated);
  std::fprintf(stderr,
               "%s: note: no --config: the built-in configuration stands for the machine (config/paper-ipmsm.yaml, the "
               "paper's IPMSM: psi_m %.4g Wb, R_s %.4g Ohm, rated %.4g A peak at %.4g rad/s electrical); give your "
               "machine's file with --config (docs/configuration.md)\n",
               tool, c.machine.psi_m_Wb, c.machine.r_s_Ohm, base.current_A, base.omega_el_rad_s);
  return c;
}

}  // namespace rpem::tools
