#include "rpem/io/estimate_log.hpp"

#include <limits>

#include "rpem/core/clock.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {

EstimateLogWriter::EstimateLogWriter(const std::string& path, const std::vector<std::string>& thermal_nodes)
    : out_(path, std::ios::binary | std::ios::trunc), thermal_nodes_(thermal_nodes.size()) {
  if (!out_) throw InputError(path, 0, 0, "", "cannot create file");
  out_ << "t,psi_m,r_s,psi_m_pu,r_s_pu,eps_d,eps_q,i_hat_d,i_hat_q,i_d,i_q,n_pu,"
          "psi_m_active,r_s_active,code,flags,sga_r_psi_m,sga_r_r_s,gna_det_R,regime,regime_bits";
  if (!thermal_nodes.empty()) {
    out_ << ",T_magnet_rpem,T_winding_rpem,T_coolant";
    // Per node RPEM_ESTIMATE's columns (named as RPEM_ESTIMATE's fields for the magnet and the winding).
    for (const std::string& n : thermal_nodes) {
      out_ << ",t_" << n << "_fused_C,t_" << n << "_fused_sd_C,t_" << n << "_source,t_" << n << "_observed_age_s";
    }
  }
  out_ << '\n';
}

void EstimateLogWriter::write(const core::Estimate& e, const core::RpemEstimator& core,
                              const core::ThermalEstimate* thermal) {
  const auto& d = e.detail;
  const auto& st = core.state();
  line_.clear();
  append_number(line_, core::to_seconds(e.t_ns));
  for (double v : {e.psi_m_Wb, e.r_s_Ohm, d.theta_pu[core::kPsiM], d.theta_pu[core::kRs], e.epsilon_A[0], e.epsilon_A[1],
                   e.i_hat_A[0], e.i_hat_A[1], e.i_meas_A[0], e.i_meas_A[1], e.speed_pu}) {
    append_number(line_ += ',', v);
  }
  line_ += (d.flags & core::step_flag::kPsiMActive) ? ",1" : ",0";
  line_ += (d.flags & core::step_flag::kRsActive) ? ",1" : ",0";
  line_ += ',' + std::to_string(static_cast<int>(d.code));
  line_ += ',' + std::to_string(d.flags);
  for (double v : {st.sga_hessian_pu[0], st.sga_hessian_pu[1], core::det2(st.gna_hessian_pu)}) {
    append_number(line_ += ',', v);
  }
  line_ += ',' + std::to_string(static_cast<int>(e.regime.regime));
  line_ += ',' + std::to_string(e.regime.bits);
  if (thermal_nodes_ > 0) {
    // Before the filter's first step: nan (not yet estimated).
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    const bool on = thermal != nullptr && thermal->started;
    static const core::ThermalEstimate kNotStarted{};
    for (double v :
         {on ? thermal->t_magnet_rpem_C : kNaN, on ? thermal->t_winding_rpem_C : kNaN, on ? thermal->coolant_C : kNaN}) {
      append_number(line_ += ',', v);
    }
    for (std::size_t i = 0; i < thermal_nodes_; ++i) {
      const core::ThermalNodeReport n = core::report_node(on ? *thermal : kNotStarted, static_cast<int>(i), e.t_ns);
      append_number(line_ += ',', n.t_C);
      append_number(line_ += ',', n.sd_K);
      line_ += static_cast<char>(',');
      line_ += static_cast<char>('0' + static_cast<int>(n.source));
      append_number(line_ += ',', n.observed_age_s);
    }
  }
  line_ += '\n';
  out_ << line_;
}

}  // namespace rpem::io
