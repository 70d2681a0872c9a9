#include "indep_vesc/plant.hpp"

#include <cassert>
#include <cmath>

namespace indep::vesc {

namespace {

/// σ(x) = x/√(1 + x²): a smooth sign, for the dead time's error and the bearing friction around zero.
double smooth_sign(double x) { return x / std::sqrt(1.0 + x * x); }

}  // namespace

Plant::Plant(const PlantParams& p) : p_(p) {
  assert(p.l_d_H > 0.0 && p.l_q_H > 0.0 && p.inertia_kgm2 > 0.0 && p.pole_pairs > 0);
}

void Plant::set_psi_m(double psi_m_Wb) { p_.psi_m_Wb = psi_m_Wb; }

Vec2 Plant::current_dq(const PlantState& x) const {
  const Vec2 psi_dq = park(x.psi_ab_Wb, x.theta_el_rad);
  return {(psi_dq.x - p_.psi_m_Wb) / p_.l_d_H, psi_dq.y / p_.l_q_H};
}

Vec2 Plant::current_ab(const PlantState& x) const { return inverse_park(current_dq(x), x.theta_el_rad); }

double Plant::torque_Nm(const PlantState& x) const {
  const Vec2 i = current_ab(x);
  return 1.5 * p_.pole_pairs * (x.psi_ab_Wb.x * i.y - x.psi_ab_Wb.y * i.x);
}

double Plant::load_torque_Nm(double w) const {
  return p_.coulomb_Nm * smooth_sign(w / p_.coulomb_band_rad_s) + p_.viscous_Nm_s * w + p_.drag_Nm_s2 * w * std::fabs(w) +
         p_.external_Nm;
}

double Plant::magnetic_energy_J(const PlantState& x) const {
  const Vec2 i = current_dq(x);
  return 1.5 * 0.5 * (p_.l_d_H * i.x * i.x + p_.l_q_H * i.y * i.y);
}

double Plant::kinetic_energy_J(const PlantState& x) const {
  return 0.5 * p_.inertia_kgm2 * x.omega_m_rad_s * x.omega_m_rad_s;
}

Plant::Rate Plant::rate_on(const PlantState& x, const std::array<double, 3>& leg_V, double dead_V) const {
  const double c = std::cos(x.theta_el_rad), s = std::sin(x.theta_el_rad);
  const Vec2 psi_dq{c * x.psi_ab_Wb.x + s * x.psi_ab_Wb.y, -s * x.psi_ab_Wb.x + c * x.psi_ab_Wb.y};
  const Vec2 i_dq{(psi_dq.x - p_.psi_m_Wb) / p_.l_d_H, psi_dq.y / p_.l_q_H};
  const Vec2 i_ab{c * i_dq.x - s * i_dq.y, s * i_dq.x + c * i_dq.y};
  std::array<double, 3> v = leg_V;
  if (dead_V != 0.0) {
    const std::array<double, 3> i_abc = inverse_clarke(i_ab);
    for (int k = 0; k < 3; ++k) v[k] -= dead_V * smooth_sign(i_abc[k] / p_.dead_band_A);
  }
  const Vec2 v_ab = clarke(v);
  Rate r;
  r.dpsi = v_ab - p_.r_s_Ohm * i_ab;
  r.dtheta = p_.pole_pairs * x.omega_m_rad_s;
  const double t_e = 1.5 * p_.pole_pairs * (x.psi_ab_Wb.x * i_ab.y - x.psi_ab_Wb.y * i_ab.x);
  const double t_l = load_torque_Nm(x.omega_m_rad_s);
  r.domega = (t_e - t_l) / p_.inertia_kgm2;
  r.v_dq = {c * v_ab.x + s * v_ab.y, -s * v_ab.x + c * v_ab.y};
  r.i_dq = i_dq;
  r.p_in = 1.5 * v_ab.dot(i_ab);
  r.p_cu = 1.5 * p_.r_s_Ohm * i_ab.dot(i_ab);
  r.p_load = t_l * x.omega_m_rad_s;
  r.p_shaft = t_e * x.omega_m_rad_s;
  return r;
}

Plant::Rate Plant::rate_off(const PlantState& x) const {
  Rate r;
  r.dtheta = p_.pole_pairs * x.omega_m_rad_s;
  const double t_l = load_torque_Nm(x.omega_m_rad_s);
  r.domega = -t_l / p_.inertia_kgm2;
  r.v_dq = {0.0, r.dtheta * p_.psi_m_Wb};  // the open terminals carry the back EMF d(ψm·e^{jθ})/dt
  r.p_load = t_l * x.omega_m_rad_s;
  return r;
}

template <class F>
IntervalResult Plant::rk4(PlantState& x, double h, const F& rate) const {
  auto advance = [&](const Rate& k, double dt) {
    PlantState s = x;
    s.psi_ab_Wb = x.psi_ab_Wb + dt * k.dpsi;
    s.theta_el_rad = x.theta_el_rad + dt * k.dtheta;
    s.omega_m_rad_s = x.omega_m_rad_s + dt * k.domega;
    return s;
  };
  const Rate k1 = rate(x);
  const Rate k2 = rate(advance(k1, 0.5 * h));
  const Rate k3 = rate(advance(k2, 0.5 * h));
  const Rate k4 = rate(advance(k3, h));
  const double w = h / 6.0;
  x.psi_ab_Wb = x.psi_ab_Wb + w * (k1.dpsi + 2.0 * k2.dpsi + 2.0 * k3.dpsi + k4.dpsi);
  x.theta_el_rad += w * (k1.dtheta + 2.0 * k2.dtheta + 2.0 * k3.dtheta + k4.dtheta);
  x.omega_m_rad_s += w * (k1.domega + 2.0 * k2.domega + 2.0 * k3.domega + k4.domega);
  IntervalResult out;
  // Stage values weighted 1, 2, 2, 1: Simpson's rule on the interval (k2 and k3 both approximate the middle).
  out.v_dq_mean_V = (1.0 / 6.0) * (k1.v_dq + 2.0 * k2.v_dq + 2.0 * k3.v_dq + k4.v_dq);
  out.i_dq_mean_A = (1.0 / 6.0) * (k1.i_dq + 2.0 * k2.i_dq + 2.0 * k3.i_dq + k4.i_dq);
  out.energy_in_J = w * (k1.p_in + 2.0 * k2.p_in + 2.0 * k3.p_in + k4.p_in);
  out.energy_cu_J = w * (k1.p_cu + 2.0 * k2.p_cu + 2.0 * k3.p_cu + k4.p_cu);
  out.energy_load_J = w * (k1.p_load + 2.0 * k2.p_load + 2.0 * k3.p_load + k4.p_load);
  out.energy_shaft_J = w * (k1.p_shaft + 2.0 * k2.p_shaft + 2.0 * k3.p_shaft + k4.p_shaft);
  return out;
}

IntervalResult Plant::step_on(PlantState& x, double h, const std::array<double, 3>& leg_V, double v_dc_V) const {
  const double dead_V = p_.t_dead_s * p_.f_sw_Hz * v_dc_V;
  return rk4(x, h, [&](const PlantState& s) { return rate_on(s, leg_V, dead_V); });
}

IntervalResult Plant::step_off(PlantState& x, double h) const {
  IntervalResult r = rk4(x, h, [&](const PlantState& s) { return rate_off(s); });
  open_phases(x);
  return r;
}

void Plant::open_phases(PlantState& x) const { x.psi_ab_Wb = inverse_park({p_.psi_m_Wb, 0.0}, x.theta_el_rad); }

}  // namespace indep::vesc
