#include "rpem/core/predictor.hpp"

namespace rpem::core {
namespace {

/// Forcing of the current equation: B·u + f(n, ψ̂m).
Vec2 current_forcing(const MachinePu& m, double omega_n, double n_pu, const Vec2& u_pu) noexcept {
  return {omega_n * u_pu[0] / m.x_d_pu, omega_n * (u_pu[1] - n_pu * m.psi_m_pu) / m.x_q_pu};
}

/// Forcing of the ψ̂m-sensitivity: ∂f/∂ψ̂m.
Vec2 psi_forcing(const MachinePu& m, double omega_n, double n_pu) noexcept {
  return {0.0, -omega_n * n_pu / m.x_q_pu};
}

/// Forcing of the r̂s-sensitivity: (∂A/∂r̂s)·î.
Vec2 rs_forcing(const MachinePu& m, double omega_n, const Vec2& i_hat) noexcept {
  return {-omega_n * i_hat[0] / m.x_d_pu, -omega_n * i_hat[1] / m.x_q_pu};
}

}  // namespace

void predict(const MachinePu& model, double omega_n, Discretization method, const PredictorInterval& iv,
             PredictorState& s) noexcept {
  const double h = iv.dt_s;
  const Mat2 a_start = system_matrix(model, omega_n, iv.n_start_pu);
  const Vec2 i_prev = s.i_hat_pu;

  if (method == Discretization::kExplicitEuler) {
    s.i_hat_pu = i_prev + h * (a_start * i_prev + current_forcing(model, omega_n, iv.n_start_pu, iv.u_start_pu));
    s.gradient.col(kPsiM) += h * (a_start * s.gradient.col(kPsiM) + psi_forcing(model, omega_n, iv.n_start_pu));
    s.gradient.col(kRs) += h * (a_start * s.gradient.col(kRs) + rs_forcing(model, omega_n, i_prev));
    return;
  }

  const Mat2 a_end = system_matrix(model, omega_n, iv.n_end_pu);
  const Mat2 m_inv = inverse2(Mat2::Identity() - 0.5 * h * a_end);
  const Mat2 n_start = Mat2::Identity() + 0.5 * h * a_start;

  s.i_hat_pu = m_inv * (n_start * i_prev + 0.5 * h *
                                               (current_forcing(model, omega_n, iv.n_start_pu, iv.u_start_pu) +
                                                current_forcing(model, omega_n, iv.n_end_pu, iv.u_end_pu)));
  s.gradient.col(kPsiM) =
      m_inv * (n_start * s.gradient.col(kPsiM) +
               0.5 * h * (psi_forcing(model, omega_n, iv.n_start_pu) + psi_forcing(model, omega_n, iv.n_end_pu)));
  s.gradient.col(kRs) =
      m_inv * (n_start * s.gradient.col(kRs) +
               0.5 * h * (rs_forcing(model, omega_n, i_prev) + rs_forcing(model, omega_n, s.i_hat_pu)));
}

Mat2 transition_matrix(const MachinePu& model, double omega_n, Discretization method, double dt_s,
                       double n_pu) noexcept {
  const Mat2 a = system_matrix(model, omega_n, n_pu);
  if (method == Discretization::kExplicitEuler) {
    return Mat2::Identity() + dt_s * a;
  }
  return inverse2(Mat2::Identity() - 0.5 * dt_s * a) * (Mat2::Identity() + 0.5 * dt_s * a);
}

}  // namespace rpem::core
