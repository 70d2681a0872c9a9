#include "rpem/core/predictor.hpp"

namespace rpem::core {
namespace {

/// The model's coefficients for one call.
struct Coefficients {
  double wd;  ///< ω_n/x_d
  double wq;  ///< ω_n/x_q
  const MachinePu& m;

  /// A(n) of Eq_FullOrderModel: ω_n·[−r/x_d, n·x_q/x_d; −n·x_d/x_q, −r/x_q].
  [[nodiscard]] Mat2 system(double n) const noexcept {
    Mat2 a;
    a << -wd * m.r_s_pu, wd * n * m.x_q_pu, -wq * n * m.x_d_pu, -wq * m.r_s_pu;
    return a;
  }
  /// Forcing of the current equation: B·u + f(n, ψ̂m).
  [[nodiscard]] Vec2 current_forcing(double n, const Vec2& u) const noexcept {
    return {wd * u[0], wq * (u[1] - n * m.psi_m_pu)};
  }
  /// Forcing of the ψ̂m-sensitivity: ∂f/∂ψ̂m.
  [[nodiscard]] Vec2 psi_forcing(double n) const noexcept { return {0.0, -wq * n}; }
  /// Forcing of the r̂s-sensitivity: (∂A/∂r̂s)·î.
  [[nodiscard]] Vec2 rs_forcing(const Vec2& i_hat) const noexcept { return {-wd * i_hat[0], -wq * i_hat[1]}; }
};

}  // namespace

void predict(const MachinePu& model, const PredictorCoefficients& pc, Discretization method,
             const PredictorInterval& iv, PredictorState& s, Gradients gradients) noexcept {
  const Coefficients c{pc.wd, pc.wq, model};
  const double h = iv.dt_s;
  const Mat2 a_start = c.system(iv.n_start_pu);
  const Vec2 i_prev = s.i_hat_pu;

  if (method == Discretization::kExplicitEuler) {
    s.i_hat_pu = i_prev + h * (a_start * i_prev + c.current_forcing(iv.n_start_pu, iv.u_start_pu));
    if (gradients == Gradients::kSkip) return;
    s.gradient.col(kPsiM) += h * (a_start * s.gradient.col(kPsiM) + c.psi_forcing(iv.n_start_pu));
    s.gradient.col(kRs) += h * (a_start * s.gradient.col(kRs) + c.rs_forcing(i_prev));
    return;
  }

  const Mat2 a_end = iv.n_end_pu == iv.n_start_pu ? a_start : c.system(iv.n_end_pu);
  const Mat2 m_inv = inverse2(Mat2::Identity() - 0.5 * h * a_end);
  const Mat2 n_start = Mat2::Identity() + 0.5 * h * a_start;

  s.i_hat_pu = m_inv * (n_start * i_prev + 0.5 * h *
                                               (c.current_forcing(iv.n_start_pu, iv.u_start_pu) +
                                                c.current_forcing(iv.n_end_pu, iv.u_end_pu)));
  if (gradients == Gradients::kSkip) return;
  s.gradient.col(kPsiM) =
      m_inv * (n_start * s.gradient.col(kPsiM) + 0.5 * h * (c.psi_forcing(iv.n_start_pu) + c.psi_forcing(iv.n_end_pu)));
  s.gradient.col(kRs) =
      m_inv * (n_start * s.gradient.col(kRs) + 0.5 * h * (c.rs_forcing(i_prev) + c.rs_forcing(s.i_hat_pu)));
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
