#include "rpem/core/estimator.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/assert.hpp"

namespace rpem::core {
namespace {

bool finite(const EstimatorSample& s) noexcept {
  const auto& iv = s.interval;
  return all_finite(iv.dt_s, iv.n_start_pu, iv.n_end_pu, iv.u_start_pu, iv.u_end_pu, s.i_meas_pu);
}

/// γ_0 are per nominal sample; a longer or shorter interval scales them so that the adaptation time
/// constant T_0 = T_samp/γ_0 stays fixed in seconds. Capped at 1 (a filter gain above 1 is unstable).
Vec2 scaled(const Vec2& gamma, double factor) noexcept { return (gamma * factor).cwiseMin(1.0); }

bool finite(const SteadyStateSample& s) noexcept {
  return std::isfinite(s.dt_s) && std::isfinite(s.n_pu) && s.u_pu.allFinite() && s.i_meas_pu.allFinite() &&
         std::isfinite(s.x_d_pu) && std::isfinite(s.x_q_pu) && s.i_gradient_pu.allFinite() && std::isfinite(s.n_gradient_pu);
}

/// The GNA matrix Hessian has one forgetting factor: that of the parameter being estimated
/// (tab_psimgains gives one per estimation case); outside both regions the slower one.
double gna_hessian_sequence(const Schedule& active, const Vec2& gamma_r) noexcept {
  if (active.psi_m && !active.r_s) return gamma_r[kPsiM];
  if (active.r_s && !active.psi_m) return gamma_r[kRs];
  return gamma_r.minCoeff();
}

}  // namespace

// The exact discrete counterpart of a first-order filter with that rate, so a time constant holds at any
// sample rate (≈ rate·dt for rate·dt ≪ 1, as scaled() gives; never above 1).
Vec2 per_interval(const Vec2& rate_per_s, double dt_s) noexcept {
  return {-std::expm1(-rate_per_s[0] * dt_s), -std::expm1(-rate_per_s[1] * dt_s)};
}

void PointGains::start(const GainSequences& rates_per_s, double nominal_period_s) noexcept {
  weight.hessian = per_interval(rates_per_s.hessian, nominal_period_s).cwiseInverse();
  weight.gain = per_interval(rates_per_s.gain, nominal_period_s).cwiseInverse();
  counted = false;
}

GainSequences PointGains::at(const GainSequences& rates_per_s, std::int64_t t_ns) const noexcept {
  const double dt_s = counted ? std::max(0.0, 1e-9 * static_cast<double>(t_ns - last_ns)) : 0.0;
  const auto gains = [dt_s](const Vec2& s, const Vec2& rate) {
    Vec2 g;
    for (int j = 0; j < 2; ++j) g[j] = 1.0 / (1.0 + std::exp(-rate[j] * dt_s) * s[j]);  // a rate of 0: S = ∞, γ = 0
    return g;
  };
  return {gains(weight.hessian, rates_per_s.hessian), gains(weight.gain, rates_per_s.gain)};
}

void PointGains::count(const GainSequences& gains, std::int64_t t_ns) noexcept {
  weight = {gains.hessian.cwiseInverse(), gains.gain.cwiseInverse()};
  last_ns = t_ns;
  counted = true;
}

RpemEstimator::RpemEstimator(const EstimatorConfig& config) noexcept {
  reconfigure(config);
  reset();
}

void RpemEstimator::reset() noexcept {
  state_.theta_pu = config_.initial_theta_pu;
  (void)project(config_.bounds, state_.theta_pu);
  state_.sga_hessian_pu = config_.initial_sga_hessian_pu;
  state_.gna_hessian_pu = config_.initial_gna_hessian_pu;
  state_.predictor = PredictorState{};
  state_.synchronized = false;
  state_.epsilon_valid = false;
}

void RpemEstimator::set_theta(const Vec2& theta_pu) noexcept {
  state_.theta_pu = theta_pu;
  (void)project(config_.bounds, state_.theta_pu);
  state_.synchronized = false;
  state_.epsilon_valid = false;
}

void RpemEstimator::reconfigure(const EstimatorConfig& config) noexcept {
  config_ = config;
  coefficients_ = PredictorCoefficients::of(config.model, config.omega_n_rad_s);
  inverse_nominal_period_ = 1.0 / config.nominal_sample_period_s;
  inverse_r_min_ = 1.0 / config.bounds.min_pu[kRs];
  // With steady-state forms for both parameters the dynamic gradients would be computed for nothing.
  gradients_ = config.gradient_psi_m == GradientForm::kDynamic || config.gradient_r_s == GradientForm::kDynamic
                   ? Gradients::kAdvance
                   : Gradients::kSkip;
  scaled_for_dt_s_ = -1.0;
  (void)project(config_.bounds, state_.theta_pu);
}

MachinePu RpemEstimator::model_for(double x_d_pu, double x_q_pu) const noexcept {
  const bool own = x_d_pu > 0.0 && x_q_pu > 0.0;
  // Made whole, not copied and patched: the per-sample path then keeps it in registers.
  return {state_.theta_pu[kRs], own ? x_d_pu : config_.model.x_d_pu, own ? x_q_pu : config_.model.x_q_pu,
          state_.theta_pu[kPsiM]};
}

void RpemEstimator::synchronize(const EstimatorSample& sample, const MachinePu& model) noexcept {
  const double gap = sample.interval.dt_s;
  const bool carry = state_.synchronized && state_.epsilon_valid && gap > 0.0 && gap <= config_.max_gap_carry_s;
  if (carry) {
    state_.predictor.i_hat_pu = sample.i_meas_pu - state_.last_epsilon_pu;  // gradients carry on too
  } else {
    state_.predictor.i_hat_pu = sample.i_meas_pu;
    // Start the dynamic gradients at their equilibrium so they need no settling time.
    state_.predictor.gradient = steady_state_gradients(model, sample.interval.n_end_pu, sample.i_meas_pu);
    state_.epsilon_valid = false;
  }
  state_.synchronized = true;
}

Mat2 RpemEstimator::select_gradient(const MachinePu& model, double n_pu) const noexcept {
  Mat2 steady = steady_state_gradients(model, n_pu, state_.predictor.i_hat_pu);  // not const: returned by move
  if (gradients_ == Gradients::kSkip) return steady;  // both forms steady-state (decided in reconfigure)
  Mat2 g = state_.predictor.gradient;
  if (config_.gradient_psi_m == GradientForm::kSteadyState) g.col(kPsiM) = steady.col(kPsiM);
  if (config_.gradient_r_s == GradientForm::kSteadyState) g.col(kRs) = steady.col(kRs);
  return g;
}

EstimatorOutput RpemEstimator::predicted_only(StepCode code, const Vec2& epsilon, const Vec2& i_hat) const noexcept {
  EstimatorOutput out = held(code);
  out.epsilon_pu = epsilon;
  out.i_hat_pu = i_hat;
  return out;
}

// Judged where the update acts: Ψᵀε, the sample's evidence on each parameter (every gain moves θ̂ through it),
// against the largest a θ in D_M explains, |ΨᵀΨ|·Δθ with Δθ the distance from θ̂ to D_M's far bound. ε is linear
// in ψm; in r_s it is convex (î = u/r̂ at standstill), where the exact error exceeds the linear one by at most
// r̂/r_min: the r_s column takes that factor. An error along no column (an inverter's voltage error on d at a
// crawl, i_d held at 0) moves nothing and is not judged (docs/derivations.md §14). Inlined into step(): every
// judged sample pays it, and SGA's update forms the same Ψᵀε.
[[gnu::always_inline]] inline Vec2 RpemEstimator::beyond_explained(const Update& u) const noexcept {
  const Vec2& th = state_.theta_pu;
  const ParameterBounds& b = config_.bounds;
  const double d_psi = std::max(th[kPsiM] - b.min_pu[kPsiM], b.max_pu[kPsiM] - th[kPsiM]);
  const double d_r = std::max(th[kRs] - b.min_pu[kRs], b.max_pu[kRs] - th[kRs]) * std::max(1.0, th[kRs] * inverse_r_min_);
  const Mat2& g = u.gradient;
  const double pp = g.col(kPsiM).squaredNorm(), rr = g.col(kRs).squaredNorm();  // ΨᵀΨ: symmetric, three products
  const double pr = std::abs(g.col(kPsiM).dot(g.col(kRs)));
  return Vec2(std::abs(g.col(kPsiM).dot(u.epsilon_pu)) - (pp * d_psi + pr * d_r),
              std::abs(g.col(kRs).dot(u.epsilon_pu)) - (pr * d_psi + rr * d_r));
}

bool RpemEstimator::beyond_noise(const Update& u, const Admission& admission, const Vec2& beyond) const noexcept {
  // ε's noise covariance C: the current's, and the voltage's and the speed's (through n·ψ̂m) through the
  // steady state, M̂⁻¹ = [r̂ n·x_q; −n·x_d r̂]/D; the evidence's variance is Ψ_jᵀ·C·Ψ_j per column.
  const MachinePu& m = u.model;
  const double n = u.n_pu, n2 = n * n, r2 = m.r_s_pu * m.r_s_pu;
  const double d = steady_state_denominator(m, n), inv_d2 = 1.0 / (d * d);
  const double emf = m.psi_m_pu * m.psi_m_pu * admission.var_n_pu;
  const double xq2 = m.x_q_pu * m.x_q_pu, xd2 = m.x_d_pu * m.x_d_pu;
  Mat2 c;
  c(0, 0) = admission.var_i_pu + inv_d2 * ((r2 + n2 * xq2) * admission.var_u_pu + n2 * xq2 * emf);
  c(1, 1) = admission.var_i_pu + inv_d2 * ((r2 + n2 * xd2) * admission.var_u_pu + r2 * emf);
  c(0, 1) = c(1, 0) = inv_d2 * m.r_s_pu * n * ((m.x_q_pu - m.x_d_pu) * admission.var_u_pu + m.x_q_pu * emf);
  const Mat2& g = u.gradient;
  const Vec2 var = (g.transpose() * c * g).diagonal();
  const double nu2 = config_.outlier_bound_sigma * config_.outlier_bound_sigma;
  return (beyond[kPsiM] > 0.0 && beyond[kPsiM] * beyond[kPsiM] > nu2 * var[kPsiM]) ||
         (beyond[kRs] > 0.0 && beyond[kRs] * beyond[kRs] > nu2 * var[kRs]);
}

[[gnu::always_inline]] inline bool RpemEstimator::outlier(const Update& u, const Admission& admission) const noexcept {
  const Vec2 beyond = beyond_explained(u);
  return (beyond[kPsiM] > 0.0 || beyond[kRs] > 0.0) && beyond_noise(u, admission, beyond);
}

EstimatorOutput RpemEstimator::held(StepCode code) const noexcept {
  EstimatorOutput out;
  out.theta_pu = state_.theta_pu;
  out.i_hat_pu = state_.predictor.i_hat_pu;
  out.code = code;
  out.flags = state_.frozen ? step_flag::kFrozen : 0;
  return out;
}

// The update both sample kinds share: eq:GainSchedule, the algorithm's gain, θ̂ += L·ε, eq:paramsubset.
// Inlined into step(): the native per-sample path keeps `model` and the gradient in registers.
[[gnu::always_inline]] inline EstimatorOutput RpemEstimator::update(const Update& u, const Vec2& gamma_r,
                                                                    const Vec2& gamma_l,
                                                                    const Admission& admission) noexcept {
  // eq:GainSchedule says where a parameter is identifiable at all; the sample's regime, whether its term
  // stands out of the noise here (docs/derivations.md §13): a parameter adapts where both hold.
  Schedule active = schedule(config_.scheduler, u.n_pu);
  active.psi_m = active.psi_m && admission.psi_m && config_.adapt_psi_m && !state_.frozen;
  active.r_s = active.r_s && admission.r_s && config_.adapt_r_s && !state_.frozen;

  GainOutput gain;
  Vec2 change = Vec2::Zero();  // L·ε, before eq:GainSchedule
  switch (config_.algorithm) {
    case Algorithm::kSga: {
      // L·ε = scale ⊙ (Ψ·ε): Ψ·ε is formed while the gain's division runs, and one product follows it
      // on the sample-to-sample chain; L itself (for the output) is off that chain.
      const SgaScale s = sga_scale(u.gradient, gamma_r, gamma_l, config_.floors, state_.sga_hessian_pu);
      const Mat2& g = u.gradient;
      change = s.scale.cwiseProduct(Vec2(g.col(kPsiM).dot(u.epsilon_pu), g.col(kRs).dot(u.epsilon_pu)));
      gain = {sga_matrix(s.scale, g), s.flags};
      break;
    }
    case Algorithm::kGna: {
      const int only = u.steady_state && active.psi_m != active.r_s ? (active.psi_m ? kPsiM : kRs) : kBothParameters;
      gain =
          gna_gain(u.gradient, gna_hessian_sequence(active, gamma_r), gamma_l, config_.floors, state_.gna_hessian_pu, only);
      change = gain.gain * u.epsilon_pu;
      break;
    }
    case Algorithm::kPhyInt:
      gain = phyint_gain(MachinePu(u.model), u.n_pu, u.i_gain_pu, gamma_l,
                         config_.floors);  // a copy: `model` stays in registers
      change = gain.gain * u.epsilon_pu;
      break;
  }
  apply_schedule(active, gain.gain);
  // θ̂ += L·ε and eq:paramsubset, a parameter at a time and only where eq:GainSchedule lets it adapt (a
  // parameter held is inside D_M already: every path that sets θ̂ projects it). Element by element: a
  // whole-vector store would make the held parameter, which the next sample's predictor reads first,
  // wait for the adapted one at the end of this sample's dependency chain (store forwarding).
  // The output's θ̂ is made from scalars kept in registers: a whole-vector load right after element stores
  // (of the state, or of a local Vec2 on the stack) cannot be forwarded from them and waits for both.
  unsigned clamped = 0;
  double psi_m = state_.theta_pu[kPsiM], r_s = state_.theta_pu[kRs];
  const auto adapt = [&](int j, bool adapts, double& value) {
    RPEM_ASSERT(adapts || !(value < config_.bounds.min_pu[j] || value > config_.bounds.max_pu[j]),
                "a held parameter is inside D_M: every path that sets theta projects it");
    if (!adapts) return;
    value += change[j];
    clamped |= static_cast<unsigned>(project(config_.bounds, j, value)) << j;
    state_.theta_pu[j] = value;
  };
  adapt(kPsiM, active.psi_m, psi_m);
  adapt(kRs, active.r_s, r_s);

  // The flags by shifts, no branches: the gain's and the projection's bits are laid out as step_flag's.
  static_assert(step_flag::kGainFloored == gain_flag::kFloored && step_flag::kPseudoInverse == gain_flag::kPseudoInverse);
  static_assert(step_flag::kProjectedPsiM == 1U << (kPsiM + 2) && step_flag::kProjectedRs == 1U << (kRs + 2));
  const auto flags = static_cast<std::uint16_t>(
      (state_.frozen ? step_flag::kFrozen : 0U) | (gain.flags & (gain_flag::kFloored | gain_flag::kPseudoInverse)) |
      (clamped << 2) | (static_cast<unsigned>(active.psi_m) * step_flag::kPsiMActive) |
      (static_cast<unsigned>(active.r_s) * step_flag::kRsActive));
  Vec2 theta;
  theta[kPsiM] = psi_m;
  theta[kRs] = r_s;
  return {theta, u.epsilon_pu, u.i_hat_pu, u.gradient, gain.gain, StepCode::kAdapted, flags};  // every member: no zero fill
}

[[gnu::flatten]] EstimatorOutput RpemEstimator::step(const EstimatorSample& sample, const Admission& admission) noexcept {
  if (!finite(sample)) {
    state_.synchronized = false;
    state_.epsilon_valid = false;
    return held(StepCode::kRejectedNonFinite);
  }
  const auto& iv = sample.interval;
  const MachinePu model = model_for(sample.x_d_pu, sample.x_q_pu);
  if (sample.resync || !state_.synchronized || !(iv.dt_s > 0.0) || iv.dt_s > config_.max_sample_interval_s) {
    synchronize(sample, model);
    return held(StepCode::kSynchronized);
  }

  // Saturation extensions give each sample its own inductances (two divisions); else the cached ones.
  // A branch, not a select: the divisions would otherwise compete with the predictor's for the divider.
  PredictorCoefficients coefficients = coefficients_;
  if (sample.x_d_pu > 0.0) [[unlikely]]
    coefficients = PredictorCoefficients::of(model, config_.omega_n_rad_s);
  // Predicted on a local copy, stored once: î, on the dependency chain, stays in registers.
  PredictorState predictor = state_.predictor;
  predict(model, coefficients, config_.discretization, iv, predictor, gradients_);
  state_.predictor = predictor;
  const Vec2 i_hat = predictor.i_hat_pu;
  const double i_max = config_.max_predicted_current_pu;  // a comparison with NaN fails: not finite
  const Mat2& g = predictor.gradient;
  if (!(std::abs(i_hat[0]) <= i_max && std::abs(i_hat[1]) <= i_max) ||
      (gradients_ == Gradients::kAdvance && !all_finite(g.col(0), g.col(1)))) {
    state_.epsilon_valid = false;
    synchronize(sample, model);
    return held(StepCode::kPredictorDiverged);
  }

  const Vec2 epsilon = sample.i_meas_pu - i_hat;
  if (!admission.adapt) [[unlikely]] {
    // The model does not describe this sample (bridge off, frame not locked): the open-loop prediction
    // would carry its error on; start again from the measurement.
    state_.epsilon_valid = false;
    synchronize(sample, model);
    return predicted_only(StepCode::kExcluded, epsilon, i_hat);
  }
  state_.last_epsilon_pu = epsilon;
  state_.epsilon_valid = true;

  if (iv.dt_s != scaled_for_dt_s_) {  // the same interval sample after sample: scaled once
    const double factor = iv.dt_s * inverse_nominal_period_;
    const GainSequences& seq = config_.gains[static_cast<std::size_t>(config_.algorithm)];
    gamma_r_ = scaled(seq.hessian, factor);
    gamma_l_ = scaled(seq.gain, factor);
    scaled_for_dt_s_ = iv.dt_s;
  }
  const Update u{model, iv.n_end_pu, i_hat, epsilon, i_hat, select_gradient(model, iv.n_end_pu), false};
  if (admission.judge && config_.outlier_bound_sigma > 0.0 && outlier(u, admission)) [[unlikely]] {
    return predicted_only(StepCode::kOutlier, epsilon, i_hat);
  }
  return update(u, gamma_r_, gamma_l_, admission);
}

EstimatorOutput RpemEstimator::step_steady_state(const SteadyStateSample& sample,
                                                 const GainSequences& rates_per_s) noexcept {
  return step_steady_state(sample, per_interval(rates_per_s.hessian, sample.dt_s),
                           per_interval(rates_per_s.gain, sample.dt_s), Admission{});
}

EstimatorOutput RpemEstimator::step_steady_state(const SteadyStateSample& sample, const Vec2& gamma_r, const Vec2& gamma_l,
                                                 const Admission& admission) noexcept {
  if (!finite(sample)) {
    state_.epsilon_valid = false;
    return held(StepCode::kRejectedNonFinite);
  }
  const MachinePu model = model_for(sample.x_d_pu, sample.x_q_pu);
  // The steady-state prediction of §1 with the current estimates; D ≥ r̂s² > 0 inside D_M.
  const Vec2 i_hat = steady_state_current(model, sample.n_pu, sample.u_pu);
  if (!i_hat.allFinite() || i_hat.lpNorm<Eigen::Infinity>() > config_.max_predicted_current_pu) {
    state_.epsilon_valid = false;
    EstimatorOutput out = held(StepCode::kPredictorDiverged);  // a voltage no machine near the model answers
    out.i_hat_pu = i_hat;
    return out;
  }
  const Vec2 epsilon = sample.i_meas_pu - i_hat;
  state_.predictor.i_hat_pu = i_hat;
  state_.last_epsilon_pu = epsilon;
  state_.epsilon_valid = true;
  state_.synchronized = true;
  if (sample.resync || !(sample.dt_s > 0.0)) {
    EstimatorOutput out = held(StepCode::kSynchronized);
    out.epsilon_pu = epsilon;
    return out;
  }
  if (!admission.adapt) return predicted_only(StepCode::kExcluded, epsilon, i_hat);
  const Mat2 gradient = steady_state_gradients(model, sample.n_gradient_pu, sample.i_gradient_pu);
  const Update u{model, sample.n_pu, sample.i_gradient_pu, epsilon, i_hat, gradient, true};
  if (admission.judge && config_.outlier_bound_sigma > 0.0 && outlier(u, admission)) {
    return predicted_only(StepCode::kOutlier, epsilon, i_hat);
  }
  return update(u, gamma_r, gamma_l, admission);
}

}  // namespace rpem::core
