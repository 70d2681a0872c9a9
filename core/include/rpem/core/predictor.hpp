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
  double n_start_pu = 0.0;  ///< speed at t_{k−1}
  double n_end_pu = 0.0;    ///< speed at t_k
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
void predict(const MachinePu& model, const PredictorCoefficients& c, Discretization method,
             const PredictorInterval& interval, PredictorState& state, Gradients gradients = Gradients::kAdvance) noexcept;

/// The same, computing the coefficients on the way.
inline void predict(const MachinePu& model, double omega_n_rad_s, Discretization method,
                    const PredictorInterval& interval, PredictorState& state) noexcept {
  predict(model, PredictorCoefficients::of(model, omega_n_rad_s), method, interval, state);
}

/// One-step transition matrix of the discrete predictor at constant speed (for stability analysis).
[[nodiscard]] Mat2 transition_matrix(const MachinePu& model, double omega_n_rad_s, Discretization method, double dt_s,
                                     double n_pu) noexcept;

}  // namespace rpem::core
