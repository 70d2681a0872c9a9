#include "rpem/core/machine.hpp"

#include <cmath>

namespace rpem::core {

Vec2 current_derivative(const MachinePu& m, double omega_n_rad_s, double n_pu, const Vec2& i_pu, const Vec2& u_pu) noexcept {
  const double did = omega_n_rad_s / m.x_d_pu * (u_pu[0] - m.r_s_pu * i_pu[0] + n_pu * m.x_q_pu * i_pu[1]);
  const double diq =
      omega_n_rad_s / m.x_q_pu * (u_pu[1] - m.r_s_pu * i_pu[1] - n_pu * m.x_d_pu * i_pu[0] - n_pu * m.psi_m_pu);
  return {did, diq};
}

Vec2 steady_state_current(const MachinePu& m, double n_pu, const Vec2& u_pu) noexcept {
  const double d = steady_state_denominator(m, n_pu);
  const double uq_emf = u_pu[1] - n_pu * m.psi_m_pu;
  return {(m.r_s_pu * u_pu[0] + n_pu * m.x_q_pu * uq_emf) / d, (-n_pu * m.x_d_pu * u_pu[0] + m.r_s_pu * uq_emf) / d};
}

Vec2 steady_state_voltage(const MachinePu& m, double n_pu, const Vec2& i_pu) noexcept {
  return {m.r_s_pu * i_pu[0] - n_pu * m.x_q_pu * i_pu[1],
          m.r_s_pu * i_pu[1] + n_pu * m.x_d_pu * i_pu[0] + n_pu * m.psi_m_pu};
}

Vec2 steady_state_prediction_error(const MachinePu& plant, const MachinePu& model, double n_pu, const Vec2& u_pu) noexcept {
  return steady_state_current(plant, n_pu, u_pu) - steady_state_current(model, n_pu, u_pu);
}

Mat2 system_matrix(const MachinePu& m, double omega_n_rad_s, double n_pu) noexcept {
  Mat2 a;
  a << -m.r_s_pu / m.x_d_pu, n_pu * m.x_q_pu / m.x_d_pu,  //
      -n_pu * m.x_d_pu / m.x_q_pu, -m.r_s_pu / m.x_q_pu;
  return omega_n_rad_s * a;
}

std::pair<std::complex<double>, std::complex<double>> continuous_eigenvalues(const MachinePu& m, double omega_n_rad_s,
                                                                             double n_pu) noexcept {
  // Eq:lambda with 1/T_d = r_s·ω_n/x_d, 1/T_q = r_s·ω_n/x_q (Eq:TdTq).
  const double inv_td = m.r_s_pu * omega_n_rad_s / m.x_d_pu;
  const double inv_tq = m.r_s_pu * omega_n_rad_s / m.x_q_pu;
  const double half_sum = 0.5 * (inv_td + inv_tq);
  const double w = omega_n_rad_s * n_pu;
  const std::complex<double> root = std::sqrt(std::complex<double>(half_sum * half_sum - (inv_td * inv_tq + w * w), 0.0));
  return {-half_sum + root, -half_sum - root};
}

Vec2 mtpa_reference(const MachinePu& m, double torque_ref_pu) noexcept {
  const double dx = m.x_q_pu - m.x_d_pu;
  if (dx <= 1e-9 * m.x_q_pu) {
    return {0.0, torque_ref_pu / m.psi_m_pu};
  }
  // eq_refcurrents
  const double a = m.psi_m_pu / 3.0;
  const double i_d = (a - std::cbrt(a * a * a + dx * dx * torque_ref_pu * torque_ref_pu / (3.0 * m.psi_m_pu))) / dx;
  const double i_q = torque_ref_pu / (m.psi_m_pu - dx * i_d);
  return {i_d, i_q};
}

}  // namespace rpem::core
