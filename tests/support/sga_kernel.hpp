#pragma once
// The smallest SGA step we can write by hand, the baseline bench_estimator holds DriveEstimator::step
// against: scalars only, a per-unit rotor-frame sample at the nominal interval in, no frames, no checks,
// no extensions, no diagnostics. From docs/derivations.md §1, §3-§6:
//   trapezoidal predictor of î and of both gradient columns (§4, eq_PEG_psim_dynamic, eq_PEG_rs_dynamic),
//   ε = i − î, r_j ← r_j + γ_r,j·(tr{ΨΨᵀ} − r_j) (eq:SGAHessian), L_j = γ_L,j·Ψ_j/max(r_j, r_min),
//   θ̂_j ← clamp(θ̂_j + L_j·ε) where eq:GainSchedule lets j adapt.
// tests/core/test_sga_kernel.cpp holds it to RpemEstimator's numbers (SGA, dynamic gradients) so the
// baseline computes what the estimator computes. Like DriveEstimator::step it is one function call per
// sample on state kept in memory between calls (not inlined into the caller's loop, where its state
// would stay in registers from sample to sample).

#include <cmath>

#include "rpem/core/estimator.hpp"

namespace rpem::test {

struct SgaKernel {
  // Configuration (per unit; rates in 1/s).
  double wd = 0.0, wq = 0.0;  ///< ω_n/x_d, ω_n/x_q
  double x_d = 0.0, x_q = 0.0;
  double half_h = 0.0;  ///< half the sample interval [s]
  double gamma_r_psi = 0.0, gamma_r_rs = 0.0, gamma_l_psi = 0.0, gamma_l_rs = 0.0;
  double r_min = 0.0;
  double n_lim_psi = 0.0, n_lim_rs = 0.0;  ///< ψ̂m adapts where |n| > n_lim_psi, r̂s where |n| < n_lim_rs
  double psi_lo = 0.0, psi_hi = 0.0, rs_lo = 0.0, rs_hi = 0.0;
  // State.
  double psi = 0.0, rs = 0.0;      ///< θ̂
  double id = 0.0, iq = 0.0;       ///< î
  double gpd = 0.0, gpq = 0.0;     ///< dî/dψ̂m
  double grd = 0.0, grq = 0.0;     ///< dî/dr̂s
  double r_psi = 0.0, r_rs = 0.0;  ///< SGA Hessians

  /// SGA's settings of an estimator configuration, at its initial θ̂ and Hessians, for samples dt_s apart.
  static SgaKernel from(const core::EstimatorConfig& c, double dt_s) noexcept {
    const core::GainSequences& g = c.gains[static_cast<int>(core::Algorithm::kSga)];
    SgaKernel k;
    k.wd = c.omega_n_rad_s / c.model.x_d_pu;
    k.wq = c.omega_n_rad_s / c.model.x_q_pu;
    k.x_d = c.model.x_d_pu;
    k.x_q = c.model.x_q_pu;
    k.half_h = 0.5 * dt_s;
    k.gamma_r_psi = g.hessian[core::kPsiM];
    k.gamma_r_rs = g.hessian[core::kRs];
    k.gamma_l_psi = g.gain[core::kPsiM];
    k.gamma_l_rs = g.gain[core::kRs];
    k.r_min = c.floors.sga_hessian_min_pu;
    k.n_lim_psi = c.scheduler.psi_m_min_speed_pu;
    k.n_lim_rs = c.scheduler.r_s_max_speed_pu;
    k.psi_lo = c.bounds.min_pu[core::kPsiM];
    k.psi_hi = c.bounds.max_pu[core::kPsiM];
    k.rs_lo = c.bounds.min_pu[core::kRs];
    k.rs_hi = c.bounds.max_pu[core::kRs];
    k.psi = c.initial_theta_pu[core::kPsiM];
    k.rs = c.initial_theta_pu[core::kRs];
    k.r_psi = c.initial_sga_hessian_pu[core::kPsiM];
    k.r_rs = c.initial_sga_hessian_pu[core::kRs];
    return k;
  }

  /// Starts the predictor and its gradients where an estimator has synchronised them.
  void synchronize(const core::PredictorState& p) noexcept {
    id = p.i_hat_pu[0];
    iq = p.i_hat_pu[1];
    gpd = p.gradient(0, core::kPsiM), gpq = p.gradient(1, core::kPsiM);
    grd = p.gradient(0, core::kRs), grq = p.gradient(1, core::kRs);
  }

  /// One conditioned sample.
  void step(const core::EstimatorSample& s) noexcept {
    const core::PredictorInterval& iv = s.interval;
    step(iv.n_start_pu, iv.n_end_pu, iv.u_start_pu[0], iv.u_start_pu[1], iv.u_end_pu[0], iv.u_end_pu[1], s.i_meas_pu[0],
         s.i_meas_pu[1]);
  }

  // Comparisons, not std::fmax (a libm call where NaN semantics are kept).
  static double max(double a, double b) noexcept { return a < b ? b : a; }
  static double clamp(double x, double lo, double hi) noexcept { return x < lo ? lo : (x > hi ? hi : x); }

  /// One sample: speed at both ends of the interval, the held command at both ends, the measured current.
  [[gnu::noinline]] void step(double n0, double n1, double ud0, double uq0, double ud1, double uq1, double i_d,
                              double i_q) noexcept {
    // A(n) = [a11 b·n; c·n a22], the same r̂s at both ends.
    const double a11 = -wd * rs, a22 = -wq * rs, b = wd * x_q, c = -wq * x_d;
    // M = I − h/2·A(n1), N = I + h/2·A(n0).
    const double m11 = 1.0 - half_h * a11, m12 = -half_h * b * n1, m21 = -half_h * c * n1, m22 = 1.0 - half_h * a22;
    const double inv_det = 1.0 / (m11 * m22 - m12 * m21);
    const double p11 = m22 * inv_det, p12 = -m12 * inv_det, p21 = -m21 * inv_det, p22 = m11 * inv_det;  // M⁻¹
    const double n11 = 1.0 + half_h * a11, n12 = half_h * b * n0, n21 = half_h * c * n0, n22 = 1.0 + half_h * a22;
    // î: forcing B·u + f(n, ψ̂m) at both ends.
    const double fd = half_h * wd * (ud0 + ud1), fq = half_h * wq * (uq0 + uq1 - (n0 + n1) * psi);
    const double vd = n11 * id + n12 * iq + fd, vq = n21 * id + n22 * iq + fq;
    const double id_new = p11 * vd + p12 * vq, iq_new = p21 * vd + p22 * vq;
    // dî/dψ̂m: forcing [0, −wq·n].
    const double sd = n11 * gpd + n12 * gpq, sq = n21 * gpd + n22 * gpq - half_h * wq * (n0 + n1);
    gpd = p11 * sd + p12 * sq;
    gpq = p21 * sd + p22 * sq;
    // dî/dr̂s: forcing −[wd·î_d, wq·î_q] at both ends.
    const double td = n11 * grd + n12 * grq - half_h * wd * (id + id_new);
    const double tq = n21 * grd + n22 * grq - half_h * wq * (iq + iq_new);
    grd = p11 * td + p12 * tq;
    grq = p21 * td + p22 * tq;
    id = id_new;
    iq = iq_new;
    // Residual, Hessians, gains, schedule, update, clamp.
    const double ed = i_d - id, eq = i_q - iq;
    const double trace = gpd * gpd + gpq * gpq + grd * grd + grq * grq;
    r_psi += gamma_r_psi * (trace - r_psi);
    r_rs += gamma_r_rs * (trace - r_rs);
    const double speed = std::abs(n1);
    if (speed > n_lim_psi) psi = clamp(psi + gamma_l_psi / max(r_psi, r_min) * (gpd * ed + gpq * eq), psi_lo, psi_hi);
    if (speed < n_lim_rs) rs = clamp(rs + gamma_l_rs / max(r_rs, r_min) * (grd * ed + grq * eq), rs_lo, rs_hi);
  }
};

}  // namespace rpem::test
