#pragma once
// Open-loop current predictor built on the full-order model M_uθ (Eq_FullOrderModel) and the dynamic
// prediction gradients (eq_PEG_psim_dynamic, eq_PEG_rs_dynamic), all in pu in the rotor frame.
//
// Continuous model, with parameters θ̂ = [ψ̂m, r̂s]:
//   dî/dt = A(n, r̂s)·î + B·u + f(n, ψ̂m),  B = ω_n·diag(1/x_d, 1/x_q),  f = ω_n·[0, −n·ψ̂m/x_q]ᵀ
// Sensitivities g_θ = dî/dθ̂ obey the same A (so share its eigenvalues):
//   dg_ψ/dt = A·g_ψ + ω_n·[0, −n/x_q]ᵀ                        (eq_PEG_psim_dynamic)
//   dg_r/dt = A·g_r − ω_n·[î_d/x_d, î_q/x_q]ᵀ                 (eq_PEG_rs_dynamic)
//
// Trapezoidal rule over [t_{k−1}, t_k] (A-stable: every continuous eigenvalue with Re λ < 0 maps to
// |z| = |(1 + hλ/2)/(1 − hλ/2)| < 1 for all speeds and steps):
//   (I − h/2·A_k)·x_k = (I + h/2·A_{k−1})·x_{k−1} + h/2·(w_{k−1} + w_k)
// where w is each equation's forcing term. Applied to the gradients this is exactly the derivative
// of the discrete predictor with respect to θ̂, so the discrete gradients are the true gradients of
// the discrete prediction. Explicit Euler is kept for comparison (Fig_EigenTraj b) only.

#include <cstdint>

#include "rpem/core/machine.hpp"
#include "rpem/core/types.hpp"

namespace rpem::core {

enum class Discretization : std::uint8_t { kTrapezoidal = 0, kExplicitEuler = 1 };

/// One prediction interval [t_{k−1}, t_k] in the rotor frame, pu.
struct PredictorInterval {
  double dt_s = 0.0;
  double n_start_pu = 0.0;         ///< speed at t_{k−1}
  double n_end_pu = 0.0;           ///< speed at t_k
  Vec2 u_start_pu = Vec2::Zero();  ///< the held voltage command, rotor frame at t_{k−1}
  Vec2 u_end_pu = Vec2::Zero();    ///< the same stator-frame command, rotor frame at t_k
};

/// Predictor state: the predicted current and the dynamic prediction gradients Ψᵀ (columns ψ̂m, r̂s).
struct PredictorState {
  Vec2 i_hat_pu = Vec2::Zero();
  Mat2 gradient = Mat2::Zero();
};

/// ω_n/x_d and ω_n/x_q: they change only with the model inductances, so callers that step often
/// compute them once.
struct PredictorCoefficients {
  double wd = 0.0;  ///< ω_n/x_d [1/s]
  double wq = 0.0;  ///< ω_n/x_q [1/s]
  [[nodiscard]] static PredictorCoefficients of(const MachinePu& m, double omega_n_rad_s) noexcept {
    return {omega_n_rad_s / m.x_d_pu, omega_n_rad_s / m.x_q_pu};
  }
};

/// Whether predict() also advances the dynamic gradients (unneeded when only steady-state forms are
/// used, or only the current is wanted).
enum class Gradients : std::uint8_t { kAdvance = 0, kSkip = 1 };

/// Advances the predictor and its dynamic gradients by one interval. `model` carries the current
/// estimates ψ̂m, r̂s and the model inductances x_d, x_q; `c` must be PredictorCoefficients::of(model).
namespace detail {

/// The model's coefficients for one call.
struct Coefficients {
  double wd;  ///< ω_n/x_d
  double wq;  ///< ω_n/x_q
  const MachinePu& m;

  /// A(n) of Eq_FullOrderModel: ω_n·[−r/x_d, n·x_q/x_d; −n·x_d/x_q, −r/x_q].
  [[nodiscard]] Mat2 system(double n) const noexcept {
    Mat2 a;
    a.col(0) = Vec2(-wd * m.r_s_pu, -wq * n * m.x_d_pu);
    a.col(1) = Vec2(wd * n * m.x_q_pu, -wq * m.r_s_pu);
    return a;
  }
  /// Forcing of the current equation: B·u + f(n, ψ̂m).
  [[nodiscard]] Vec2 current_forcing(double n, const Vec2& u) const noexcept {
    return input(u) + m.psi_m_pu * psi_forcing(n);
  }
  /// The voltage's part of the current's forcing: B·u.
  [[nodiscard]] Vec2 input(const Vec2& u) const noexcept { return {wd * u[0], wq * u[1]}; }
  /// Forcing of the ψ̂m-sensitivity: ∂f/∂ψ̂m (f is linear in ψ̂m: current_forcing = input + ψ̂m·this).
  [[nodiscard]] Vec2 psi_forcing(double n) const noexcept { return {0.0, -wq * n}; }
  /// Forcing of the r̂s-sensitivity: (∂A/∂r̂s)·î.
  [[nodiscard]] Vec2 rs_forcing(const Vec2& i_hat) const noexcept { return {-wd * i_hat[0], -wq * i_hat[1]}; }
};

/// One trapezoidal step x_k = (I − h/2·A_k)⁻¹·((I + h/2·A_{k−1})·x_{k−1} + w), element by element:
/// A(n) = [a11, b·n; c·n, a22] has the speed only off the diagonal. (I − h/2·A_k)⁻¹ is the adjugate
/// over the determinant, formed here from r̂s and the speeds alone: the step itself, on the estimator's
/// sample-to-sample dependency chain (θ̂ → î → Ψ → L → θ̂), is then two products and a sum per element.
struct Trapezoid {
  double p11, p12, p21, p22;  ///< (I − h/2·A(n_end))⁻¹
  double n11, n12, n21, n22;  ///< I + h/2·A(n_start)

  Trapezoid(const Coefficients& c, double half_h, double n_start, double n_end) noexcept {
    const double d11 = half_h * c.wd * c.m.r_s_pu, d22 = half_h * c.wq * c.m.r_s_pu;
    const double b = half_h * c.wd * c.m.x_q_pu, cc = -half_h * c.wq * c.m.x_d_pu;
    const double m11 = 1.0 + d11, m12 = -b * n_end, m21 = -cc * n_end, m22 = 1.0 + d22;
    const double inv_det = 1.0 / (m11 * m22 - m12 * m21);
    p11 = m22 * inv_det, p12 = -m12 * inv_det, p21 = -m21 * inv_det, p22 = m11 * inv_det;
    n11 = 1.0 - d11, n12 = b * n_start, n21 = cc * n_start, n22 = 1.0 - d22;
  }
  /// x_k for the previous value x and the forcing term w = [w0, w1] (already times h/2).
  [[nodiscard]] Vec2 step(const Vec2& x, double w0, double w1) const noexcept {
    const double v0 = n11 * x[0] + n12 * x[1] + w0, v1 = n21 * x[0] + n22 * x[1] + w1;
    return {p11 * v0 + p12 * v1, p21 * v0 + p22 * v1};
  }
};

}  // namespace detail

inline void predict(const MachinePu& model, const PredictorCoefficients& pc, Discretization method,
                    const PredictorInterval& iv, PredictorState& s, Gradients gradients = Gradients::kAdvance) noexcept {
  const detail::Coefficients c{pc.wd, pc.wq, model};
  const double h = iv.dt_s;
  const Vec2 i_prev = s.i_hat_pu;

  if (method == Discretization::kExplicitEuler) {
    const Mat2 a_start = c.system(iv.n_start_pu);
    s.i_hat_pu = i_prev + h * (a_start * i_prev + c.current_forcing(iv.n_start_pu, iv.u_start_pu));
    if (gradients == Gradients::kSkip) return;
    s.gradient.col(kPsiM) += h * (a_start * s.gradient.col(kPsiM) + c.psi_forcing(iv.n_start_pu));
    s.gradient.col(kRs) += h * (a_start * s.gradient.col(kRs) + c.rs_forcing(i_prev));
    return;
  }

  const double half_h = 0.5 * h;
  const detail::Trapezoid t(c, half_h, iv.n_start_pu, iv.n_end_pu);
  // The current's forcing at both ends, B·u + ψ̂m·∂f/∂ψ̂m, with ψ̂m entering last (one product and a
  // sum on the estimator's dependency chain); ∂f/∂ψ̂m is also the ψ̂m-sensitivity's forcing.
  // Scalars: ∂f/∂ψ̂m = [0, −ω_n/x_q·n] has one element that is not zero, and a Vec2 made of a constant and
  // a computed element went through the stack (two stores, one wider load: a store-forwarding stall).
  const double w_psi_q = half_h * (c.psi_forcing(iv.n_start_pu)[1] + c.psi_forcing(iv.n_end_pu)[1]);
  const Vec2 w_u = half_h * (c.input(iv.u_start_pu) + c.input(iv.u_end_pu));
  s.i_hat_pu = t.step(i_prev, w_u[0], w_u[1] + model.psi_m_pu * w_psi_q);
  if (gradients == Gradients::kSkip) return;
  s.gradient.col(kPsiM) = t.step(s.gradient.col(kPsiM), 0.0, w_psi_q);
  const Vec2 w_rs = half_h * (c.rs_forcing(i_prev) + c.rs_forcing(s.i_hat_pu));
  s.gradient.col(kRs) = t.step(s.gradient.col(kRs), w_rs[0], w_rs[1]);
}

/// The same, computing the coefficients on the way.
inline void predict(const MachinePu& model, double omega_n_rad_s, Discretization method, const PredictorInterval& interval,
                    PredictorState& state) noexcept {
  predict(model, PredictorCoefficients::of(model, omega_n_rad_s), method, interval, state);
}

/// One-step transition matrix of the discrete predictor at constant speed (for stability analysis).
[[nodiscard]] Mat2 transition_matrix(const MachinePu& model, double omega_n_rad_s, Discretization method, double dt_s,
                                     double n_pu) noexcept;

}  // namespace rpem::core
