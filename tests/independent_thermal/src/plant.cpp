#include "indep_thermal/plant.hpp"

#include <cmath>

#include "indep_thermal/materials.hpp"
#include "indep_thermal/pi.hpp"

namespace indep_thermal {

Plant::Plant(const Machine& configured, const Parameters& p, const Profile& profile, CoolantMode mode)
    : configured_(configured), p_(p), profile_(profile), mode_(mode), c_(capacities(p)) {
  validate(p_);
  y0_.setZero();
  const double t_node = p_.coolant_start_C + p_.initial_rise_K;
  y0_(kTWinding) = t_node;
  y0_(kTIron) = t_node;
  y0_(kTRotor) = t_node;
  y0_(kTSensorLag) = t_node;
  y0_(kTCoolant) = p_.coolant_start_C;
}

State Plant::initial_state() const { return y0_; }

double Plant::stored_heat_J(const State& y) const { return c_.dot(y.head<3>() - y0_.head<3>()); }

Snapshot Plant::evaluate(double t, const State& y, bool left_limit) const {
  Snapshot s;
  s.t_s = t;
  s.y = y;
  const double t_w = y(kTWinding);
  const double t_r = y(kTRotor);
  const double t_c = y(kTCoolant);
  s.sensor_reading_C = t_c + p_.sensor_placement_gain * (y(kTSensorLag) - t_c);

  s.demand = profile_.at(t, left_limit);
  s.op = drive_currents(configured_, p_, s.demand, s.sensor_reading_C);
  s.speed_rpm = s.op.omega_el_rad_s / p_.pole_pairs * 60.0 / (2.0 * kPi);
  const double omega_mech = s.op.omega_el_rad_s / p_.pole_pairs;
  s.losses = compute_losses(p_, s.op, t_w, t_r);
  s.g = conductances(p_, omega_mech);
  s.u = steady_state_voltage(p_, s.op, t_w, t_r);
  s.r_s_dc_Ohm = copper_resistance_Ohm(p_, t_w);
  s.r_s_ac_Ohm = s.r_s_dc_Ohm * ac_resistance_factor(p_, std::abs(s.op.omega_el_rad_s) / (2.0 * kPi));
  s.psi_m_Wb = magnet_flux_Wb(p_, t_r);

  const Eigen::Vector3d temps = y.head<3>();
  const Eigen::Vector3d g_c = s.g.to_coolant();
  const Eigen::Vector3d losses(s.losses.winding(), s.losses.iron(), s.losses.rotor());
  const Eigen::Vector3d outflow = s.g.matrix() * temps - g_c * t_c;  // heat leaving each node [W]
  s.heat_to_coolant_W = g_c.dot(temps - Eigen::Vector3d::Constant(t_c));

  s.dydt.setZero();
  s.dydt.head<3>() = (losses - outflow).cwiseQuotient(c_);
  s.dydt(kTSensorLag) = (t_w - y(kTSensorLag)) / p_.sensor_winding_tau_s;
  if (mode_ == CoolantMode::loop) {
    s.other_heat_W = p_.coolant_other_heat_share * s.losses.total();
    const double to_ambient = p_.coolant_radiator_W_K * (t_c - p_.coolant_start_C);
    s.dydt(kTCoolant) = (s.heat_to_coolant_W + s.other_heat_W - to_ambient) / p_.coolant_loop_capacity_J_K;
  }
  s.dydt(kEWinding) = losses(kWinding);
  s.dydt(kEIron) = losses(kIron);
  s.dydt(kERotor) = losses(kRotor);
  s.dydt(kECoolant) = s.heat_to_coolant_W;
  s.dydt(kIdIntegral) = s.op.i_d_A;
  s.dydt(kIqIntegral) = s.op.i_q_A;
  s.dydt(kUdIntegral) = s.u.u_d_V;
  s.dydt(kUqIntegral) = s.u.u_q_V;
  s.dydt(kOmegaIntegral) = s.op.omega_el_rad_s;
  return s;
}

}  // namespace indep_thermal
