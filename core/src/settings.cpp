#include "rpem/core/settings.hpp"

namespace rpem::core {

MachinePu to_pu(const PerUnitBase& base, const MachineSi& m) noexcept {
  return {base.resistance_pu(m.r_s_Ohm), base.inductance_pu(m.l_d_H), base.inductance_pu(m.l_q_H),
          base.flux_pu(m.psi_m_Wb)};
}

EstimatorConfig make_estimator_config(const PerUnitBase& base, const MachineSi& m,
                                      const EstimatorSettings& s) noexcept {
  EstimatorConfig c;
  static_cast<EstimatorOptions&>(c) = s;
  c.model = to_pu(base, m);
  c.omega_n_rad_s = base.omega_el_rad_s;
  c.scheduler.psi_m_min_speed_pu = base.mech_speed_rpm_to_pu(s.psi_m_min_speed_rpm);
  c.scheduler.r_s_max_speed_pu = base.mech_speed_rpm_to_pu(s.r_s_max_speed_rpm);
  c.bounds.min_pu = {base.flux_pu(s.psi_m_min_Wb), base.resistance_pu(s.r_s_min_Ohm)};
  c.bounds.max_pu = {base.flux_pu(s.psi_m_max_Wb), base.resistance_pu(s.r_s_max_Ohm)};
  c.initial_theta_pu = {base.flux_pu(s.initial_psi_m_Wb), base.resistance_pu(s.initial_r_s_Ohm)};
  return c;
}

}  // namespace rpem::core
