#include "rpem/sim/truth_log.hpp"

#include "rpem/core/clock.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::sim {

TruthLogWriter::TruthLogWriter(const std::string& path) : out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw io::InputError(path, 0, 0, "", "cannot create file");
  out_ << "t,psi_m,r_s,l_d,l_q,T_winding,T_magnet,omega_el,theta_el,torque,i_d,i_q\n";
}

void TruthLogWriter::write(const TruthRow& r) {
  line_.clear();
  io::append_number(line_, core::to_seconds(r.t_ns));
  for (double v : {r.parameters.psi_m_Wb, r.parameters.r_s_Ohm, r.l_d_H, r.l_q_H, r.t_winding_C, r.t_magnet_C,
                   r.omega_el_rad_s, r.theta_el_rad, r.torque_Nm, r.i_dq_A[0], r.i_dq_A[1]}) {
    io::append_number(line_ += ',', v);
  }
  line_ += '\n';
  out_ << line_;
}

}  // namespace rpem::sim
