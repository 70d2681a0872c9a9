#include "rpem/io/estimate_log.hpp"

#include <limits>

#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {

EstimateLogWriter::EstimateLogWriter(const std::string& path, const std::vector<std::string>& thermal_nodes)
    : out_(path, std::ios::binary | std::ios::trunc), thermal_nodes_(thermal_nodes.size()) {
  if (!out_) throw InputError(path, 0, 0, "", "cannot create file");
  out_ << "t,psi_m,r_s,psi_m_pu,r_s_pu,eps_d,eps_q,i_hat_d,i_hat_q,i_d,i_q,n_pu,"
          "psi_m_active,r_s_active,code,flags,sga_r_psi_m,sga_r_r_s,gna_det_R";
  if (!thermal_nodes.empty()) {
    out_ << ",T_magnet_rpem,T_winding_rpem,T_coolant";
    for (const std::string& n : thermal_nodes) out_ << ",T_" << n << ",sigma_" << n << ",observed_" << n << ",age_" << n;
  }
  out_ << '\n';
}

void EstimateLogWriter::write(const core::Estimate& e, const core::RpemEstimator& core, const core::ThermalEstimate* thermal) {
  const auto& d = e.detail;
  const auto& st = core.state();
  line_.clear();
  append_number(line_, 1e-9 * static_cast<double>(e.t_ns));
  for (double v : {e.psi_m_Wb, e.r_s_Ohm, d.theta_pu[core::kPsiM], d.theta_pu[core::kRs], e.epsilon_A[0],
                   e.epsilon_A[1], e.i_hat_A[0], e.i_hat_A[1], e.i_meas_A[0], e.i_meas_A[1], e.speed_pu}) {
    append_number(line_ += ',', v);
  }
  line_ += (d.flags & core::step_flag::kPsiMActive) ? ",1" : ",0";
  line_ += (d.flags & core::step_flag::kRsActive) ? ",1" : ",0";
  line_ += ',' + std::to_string(static_cast<int>(d.code));
  line_ += ',' + std::to_string(d.flags);
  for (double v : {st.sga_hessian_pu[0], st.sga_hessian_pu[1], core::det2(st.gna_hessian_pu)}) {
    append_number(line_ += ',', v);
  }
  if (thermal_nodes_ > 0) {
    // Before the filter's first step: nan (not yet estimated).
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    const bool on = thermal != nullptr && thermal->started;
    for (double v : {on ? thermal->t_magnet_rpem_C : kNaN, on ? thermal->t_winding_rpem_C : kNaN, on ? thermal->coolant_C : kNaN}) {
      append_number(line_ += ',', v);
    }
    for (std::size_t i = 0; i < thermal_nodes_; ++i) {
      const core::ThermalNodeEstimate* n = on ? &thermal->node[i] : nullptr;
      append_number(line_ += ',', n ? n->t_C : kNaN);
      append_number(line_ += ',', n ? n->sigma_K : kNaN);
      line_ += n && n->observed ? ",1" : ",0";
      append_number(line_ += ',', n ? n->age_s : kNaN);
    }
  }
  line_ += '\n';
  out_ << line_;
}

}  // namespace rpem::io
