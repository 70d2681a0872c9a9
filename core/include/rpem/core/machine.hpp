#pragma once
// The IPMSM electrical model in the rotor frame, per-unit (eq:1, Eq_FullOrderModel), and its
// closed-form steady-state analysis. Everything here is a pure function of its arguments.
//
//   u_d = r_s·i_d + (x_d/ω_n)·di_d/dt − n·x_q·i_q
//   u_q = r_s·i_q + (x_q/ω_n)·di_q/dt + n·x_d·i_d + n·ψ_m
//
// Steady state (d/dt = 0) with D = r_s² + n²·x_d·x_q:
//   i_d = ( r_s·u_d + n·x_q·(u_q − n·ψ_m)) / D
//   i_q = (−n·x_d·u_d + r_s·(u_q − n·ψ_m)) / D

#include <complex>
#include <utility>

#include "rpem/core/types.hpp"

namespace rpem::core {

/// Machine parameters in pu (paper notation: r_s, x_d, x_q, ψ_m).
struct MachinePu {
  double r_s_pu = 0.0;
  double x_d_pu = 0.0;
  double x_q_pu = 0.0;
  double psi_m_pu = 0.0;
};

/// D = r_s² + n²·x_d·x_q, the common denominator of every steady-state expression.
[[nodiscard]] inline double steady_state_denominator(const MachinePu& m, double n_pu) noexcept {
  return m.r_s_pu * m.r_s_pu + n_pu * n_pu * m.x_d_pu * m.x_q_pu;
}

/// Right-hand side di/dt [pu/s] of Eq_FullOrderModel.
[[nodiscard]] Vec2 current_derivative(const MachinePu& m, double omega_n_rad_s, double n_pu, const Vec2& i_pu,
                                      const Vec2& u_pu) noexcept;

/// Steady-state current for a constant rotor-frame voltage at constant speed.
[[nodiscard]] Vec2 steady_state_current(const MachinePu& m, double n_pu, const Vec2& u_pu) noexcept;

/// Steady-state voltage that holds a given current at constant speed.
[[nodiscard]] Vec2 steady_state_voltage(const MachinePu& m, double n_pu, const Vec2& i_pu) noexcept;

/// Electromagnetic torque τ = ψ_m·i_q + (x_d − x_q)·i_d·i_q [pu].
[[nodiscard]] inline double torque_pu(const MachinePu& m, const Vec2& i_pu) noexcept {
  return m.psi_m_pu * i_pu[1] + (m.x_d_pu - m.x_q_pu) * i_pu[0] * i_pu[1];
}

/// Steady-state prediction gradients Ψᵀ = dî/dθ̂ (columns: ψ̂m, r̂s), derived in docs/derivations.md.
/// Corrects eq:PEG_steadySTate_psim / eq:PEG_steadySTate_rs, whose printed denominator r̂_s + n²x_qx_d
/// lacks the square on r̂_s (erratum E2):
///   dî_d/dψ̂m = −n²·x_q / D,                 dî_q/dψ̂m = −n·r̂_s / D
///   dî_d/dr̂s = (−r̂_s·î_d − n·x_q·î_q) / D,   dî_q/dr̂s = (n·x_d·î_d − r̂_s·î_q) / D
/// Inline: it is on the estimator's per-sample path.
[[nodiscard]] inline Mat2 steady_state_gradients(const MachinePu& m, double n_pu, const Vec2& i_hat_pu) noexcept {
  const double inv_d = 1.0 / steady_state_denominator(m, n_pu);
  // Built a column at a time (Mat2 is column-major: element-wise stores would stall whole-column loads).
  Mat2 g;
  g.col(kPsiM) = Vec2(-n_pu * n_pu * m.x_q_pu, -n_pu * m.r_s_pu) * inv_d;
  // The r̂s column's coefficients over D first: î (on the estimator's dependency chain) enters last.
  const double r = m.r_s_pu * inv_d, nxq = n_pu * m.x_q_pu * inv_d, nxd = n_pu * m.x_d_pu * inv_d;
  g.col(kRs) = Vec2(-r * i_hat_pu[0] - nxq * i_hat_pu[1], nxd * i_hat_pu[0] - r * i_hat_pu[1]);
  return g;
}

/// Steady-state prediction error ε = i − î (eq_epsilon_steadystate) of a model with parameters `model`
/// against a machine with parameters `plant`, both driven by the same voltage; exact, not linearised.
[[nodiscard]] Vec2 steady_state_prediction_error(const MachinePu& plant, const MachinePu& model, double n_pu,
                                                 const Vec2& u_pu) noexcept;

/// Continuous-time system matrix A of Eq_FullOrderModel, di/dt = A·i + … (Eq:SystemMatrix, erratum E1:
/// the printed (2,1) element of λI − A carries the wrong sign; it must be +n·x_d·ω_n/x_q).
[[nodiscard]] Mat2 system_matrix(const MachinePu& m, double omega_n_rad_s, double n_pu) noexcept;

/// Eigenvalues of A (Eq:lambda), returned as a conjugate pair or two real values.
[[nodiscard]] std::pair<std::complex<double>, std::complex<double>> continuous_eigenvalues(const MachinePu& m,
                                                                                           double omega_n_rad_s,
                                                                                           double n_pu) noexcept;

/// MTPA current references of eq_refcurrents (the printed closed form; see docs/derivations.md for its
/// accuracy against the exact MTPA solution). Valid for x_q > x_d; falls back to i_d = 0 otherwise.
[[nodiscard]] Vec2 mtpa_reference(const MachinePu& m, double torque_ref_pu) noexcept;

}  // namespace rpem::core
