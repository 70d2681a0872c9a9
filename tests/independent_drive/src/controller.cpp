#include "indep_drive/controller.hpp"

#include <cmath>

namespace indep {

namespace {

Vec2 mtpa_at_magnitude(double magnitude, double sign, const MachineParams& m) {
  const double dl = m.l_q_H - m.l_d_H;
  double i_d = 0.0;
  if (std::abs(dl) > 1e-9 * (m.l_d_H + m.l_q_H)) {
    i_d = (m.psi_m_Wb - std::sqrt(m.psi_m_Wb * m.psi_m_Wb + 8.0 * dl * dl * magnitude * magnitude)) / (4.0 * dl);
  }
  return {i_d, sign * std::sqrt(std::max(0.0, magnitude * magnitude - i_d * i_d))};
}

double torque_of(Vec2 i, const MachineParams& m) {
  return 1.5 * m.pole_pairs * (m.psi_m_Wb * i.y + (m.l_d_H - m.l_q_H) * i.x * i.y);
}

}  // namespace

Vec2 mtpa_current(double torque, const MachineParams& m, double i_max) {
  if (torque == 0.0) return {};
  const double sign = torque > 0.0 ? 1.0 : -1.0;
  double lo = 0.0, hi = i_max;
  if (std::abs(torque_of(mtpa_at_magnitude(hi, sign, m), m)) <= std::abs(torque)) return mtpa_at_magnitude(hi, sign, m);
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (std::abs(torque_of(mtpa_at_magnitude(mid, sign, m), m)) < std::abs(torque) ? lo : hi) = mid;
  }
  return mtpa_at_magnitude(0.5 * (lo + hi), sign, m);
}

CurrentController::CurrentController(const ControllerConfig& config) : c_(config) {}

ControllerOutput CurrentController::step(const std::array<double, 3>& i_abc, double theta, double omega, double u_dc,
                                         double torque_cmd, double i_d_inject) {
  const MachineParams& m = c_.model;
  ControllerOutput out;
  const Vec2 i = park(clarke(i_abc), theta);
  out.i_ref_A = mtpa_current(torque_cmd, m, c_.current_limit_A) + Vec2{i_d_inject, 0.0};
  const Vec2 e = out.i_ref_A - i;
  const Vec2 kp{m.l_d_H * c_.bandwidth_rad_s, m.l_q_H * c_.bandwidth_rad_s};
  const double ki = m.r_s_Ohm * c_.bandwidth_rad_s;
  // Feed-forward: the steady state of the believed machine at the reference, u = R·i* + ω·J·(L·i* + ψm).
  const Vec2 ff{m.r_s_Ohm * out.i_ref_A.x - omega * m.l_q_H * out.i_ref_A.y,
                m.r_s_Ohm * out.i_ref_A.y + omega * (m.l_d_H * out.i_ref_A.x + m.psi_m_Wb)};
  integral_V_ = integral_V_ + (ki * c_.period_s) * e;
  const Vec2 prop{kp.x * e.x, kp.y * e.y};
  Vec2 u = ff + prop + integral_V_;
  const double limit = c_.voltage_margin * linear_limit_V(u_dc, c_.modulation);
  const double magnitude = u.norm();
  if (magnitude > limit) {
    u = (limit / magnitude) * u;
    integral_V_ = u - ff - prop;  // back-calculation: the integrator holds what the limit leaves
    out.saturated = true;
  }
  out.u_dq_V = u;
  out.u_abc_V = inverse_clarke(inverse_park(u, theta + omega * c_.period_s * c_.angle_advance_periods));
  out.duty = duty_cycles(out.u_abc_V, u_dc, c_.modulation);
  return out;
}

}  // namespace indep
