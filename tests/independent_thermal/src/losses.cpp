#include "indep_thermal/losses.hpp"

#include <cmath>

#include "indep_thermal/materials.hpp"
#include "indep_thermal/pi.hpp"

namespace indep_thermal {

Losses compute_losses(const Parameters& p, const OperatingPoint& op, double t_winding_C, double t_rotor_C) {
  const double f = std::abs(op.omega_el_rad_s) / (2.0 * kPi);
  const double x = f / p.rated_frequency_Hz;
  const double psi_d = magnet_flux_Wb(p, t_rotor_C) + p.l_d_H * op.i_d_A;
  const double psi_q = p.l_q_H * op.i_q_A;
  const double b = std::hypot(psi_d, psi_q) / p.psi_m_ref_Wb;
  const double i2 = op.i_d_A * op.i_d_A + op.i_q_A * op.i_q_A;
  const double n = std::abs(op.omega_el_rad_s) / p.pole_pairs / p.rated_speed_rad_s;

  Losses l;
  l.flux_rel = b;
  l.copper = 1.5 * copper_resistance_Ohm(p, t_winding_C) * ac_resistance_factor(p, f) * i2;
  const double hyst = x * std::pow(b, p.steinmetz_exponent);
  const double eddy = x * x * b * b;
  const double excess = std::pow(x * b, 1.5);
  const double eddy_share = 1.0 - p.stator_hysteresis_share - p.stator_excess_share;
  l.stator_hysteresis = p.stator_iron_rated_W * p.stator_hysteresis_share * hyst;
  l.stator_eddy = p.stator_iron_rated_W * eddy_share * eddy;
  l.stator_excess = p.stator_iron_rated_W * p.stator_excess_share * excess;
  l.rotor_iron = p.rotor_iron_rated_W * (p.rotor_hysteresis_share * hyst + (1.0 - p.rotor_hysteresis_share) * eddy);
  l.magnet = p.magnet_rated_W * x * x * i2 / (p.rated_current_A * p.rated_current_A);
  l.mechanical = p.mechanical_rated_W * (p.bearing_share * n + (1.0 - p.bearing_share) * n * n * n);
  return l;
}

}  // namespace indep_thermal
