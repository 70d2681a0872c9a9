#include "indep_thermal/materials.hpp"

namespace indep_thermal {

double copper_resistance_Ohm(const Parameters& p, double t_winding_C) {
  const double k = 1.0 / p.copper_alpha20_per_K - 20.0;  // °C below 0 °C where the linear law reaches R = 0
  return p.r_s_ref_Ohm * (k + t_winding_C) / (k + p.r_s_reference_C);
}

double ac_resistance_factor(const Parameters& p, double f_el_Hz) {
  const double x = f_el_Hz / p.rated_frequency_Hz;
  return 1.0 + p.ac_factor_at_rated * x * x;
}

double magnet_flux_Wb(const Parameters& p, double t_magnet_C) {
  const double a = p.magnet_alpha20_per_K;
  return p.psi_m_ref_Wb * (1.0 + a * (t_magnet_C - 20.0)) / (1.0 + a * (p.psi_m_reference_C - 20.0));
}

}  // namespace indep_thermal
