#include "rpem/io/flux_reading.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rpem/core/units.hpp"

namespace rpem::io {
namespace {

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

FluxReading flux_reading(const std::vector<core::AveragedSample>& samples, const MachineConfig& config) {
  const core::MachineSi& m = config.machine;
  const core::EstimatorSettings& e = config.estimator;
  const double speed_min_rad_s = core::rpm_to_rad_s(e.psi_m_min_speed_rpm) * m.rated.pole_pairs;  // electrical
  const double r_spread_Ohm = std::max(std::abs(e.r_s_max_Ohm - m.r_s_Ohm), std::abs(m.r_s_Ohm - e.r_s_min_Ohm));
  std::vector<double> psi, allowance;
  for (const core::AveragedSample& s : samples) {
    const double w = s.omega_el_rad_s;
    if (!(std::abs(w) > speed_min_rad_s) || !s.u_dq_V.allFinite() || !s.i_dq_A.allFinite()) continue;
    if (s.u_dq_V.x() == 0.0 && s.u_dq_V.y() == 0.0) continue;  // the bridge off: no applied voltage
    // The back EMF on q: what eq:1's steady state leaves of u_q once the drop and ω·L_d·i_d are taken out. The d axis
    // is not used: its ω·L_q·i_q is the configured machine's inductance at full current, which another machine's
    // configuration can make larger than any voltage the log holds.
    psi.push_back((s.u_dq_V.y() - m.r_s_Ohm * s.i_dq_A.y() - w * m.l_d_H * s.i_dq_A.x()) / w);
    allowance.push_back(e.regimes.inductance_tolerance * m.l_d_H * std::abs(s.i_dq_A.x()) +
                        r_spread_Ohm * std::abs(s.i_dq_A.y()) / std::abs(w));
  }
  if (psi.empty()) return {};
  return {psi.size(), median(psi), median(allowance)};
}

std::optional<std::string> flux_mismatch_note(const FluxReading& r, const MachineConfig& config) {
  const core::EstimatorSettings& e = config.estimator;
  if (r.windows == 0 || (r.psi_m_Wb + r.allowance_Wb >= e.psi_m_min_Wb && r.psi_m_Wb - r.allowance_Wb <= e.psi_m_max_Wb))
    return std::nullopt;
  char text[640];
  std::snprintf(text, sizeof text,
                "the log's back EMF reads psi_m %.4g Wb (the median of %zu windows that modulate above "
                "estimator.scheduler.psi_m_min_speed_rpm; +-%.2g Wb for the configuration's inductance tolerance and "
                "R_s bounds), %.3g times the configured %.4g Wb and outside estimator.bounds.psi_m_Wb [%.4g, %.4g], "
                "where the estimator cannot follow it: this configuration most likely describes another machine "
                "(without --config the tools take the paper's 1.14 Wb machine); give the machine's (--config; "
                "docs/configuration.md)",
                r.psi_m_Wb, r.windows, r.allowance_Wb, r.psi_m_Wb / config.machine.psi_m_Wb, config.machine.psi_m_Wb,
                e.psi_m_min_Wb, e.psi_m_max_Wb);
  return std::string(text);
}

}  // namespace rpem::io
