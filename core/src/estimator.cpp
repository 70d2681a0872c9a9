#include "rpem/core/estimator.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {
namespace {

bool finite(const EstimatorSample& s) noexcept {
  const auto& iv = s.interval;
  return std::isfinite(iv.dt_s) && std::isfinite(iv.n_start_pu) && std::isfinite(iv.n_end_pu) &&
         iv.u_start_pu.allFinite() && iv.u_end_pu.allFinite() && s.i_meas_pu.allFinite();
}

/// γ_0 are per nominal sample; a longer or shorter interval scales them so that the adaptation time
/// constant T_0 = T_samp/γ_0 stays fixed in seconds. Capped at 1 (a filter gain above 1 is unstable).
Vec2 scaled(const Vec2& gamma, double factor) noexcept { return (gamma * factor).cwiseMin(1.0); }

/// Rates [1/s] as the per-sample factors of an interval dt: γ = 1 − e^{−rate·dt}, the exact discrete
/// counterpart of a first-order filter with that rate, so a time constant holds at any sample rate
/// (≈ rate·dt for rate·dt ≪ 1, as scaled() gives; never above 1).
Vec2 per_interval(const Vec2& rate_per_s, double dt_s) noexcept {
  return {-std::expm1(-rate_per_s[0] * dt_s), -std::expm1(-rate_per_s[1] * dt_s)};
}

bool finite(const SteadyStateSample& s) noexcept {
  return std::isfinite(s.dt_s) && std::isfinite(s.n_pu) && s.u_pu.allFinite() && s.i_meas_pu.allFinite() &&
         std::isfinite(s.x_d_pu) && std::isfinite(s.x_q_pu) && s.i_gradient_pu.allFinite() &&
         std::isfinite(s.n_gradient_pu);
}

/// The GNA matrix Hessian has one forgetting factor: that of the parameter being estimated
/// (tab_psimgains gives one per estimation case); outside both regions the slower one.
double gna_hessian_sequence(const Schedule& active, const Vec2& gamma_r) noexcept {
  if (active.psi_m && !active.r_s) return gamma_r[kPsiM];
  if (active.r_s && !active.psi_m) return gamma_r[kRs];
  return gamma_r.minCoeff();
}

}  // namespace

RpemEstimator::RpemEstimator(const EstimatorConfig& config) noexcept
    : config_(config),
      coefficients_(PredictorCoefficients::of(config.model, config.omega_n_rad_s)),
      inverse_nominal_period_(1.0 / config.nominal_sample_period_s) {
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
  (void)project(config_.bounds, state_.theta_pu);
}

MachinePu RpemEstimator::model_for(double x_d_pu, double x_q_pu) const noexcept {
  MachinePu m = config_.model;
  m.psi_m_pu = state_.theta_pu[kPsiM];
  m.r_s_pu = state_.theta_pu[kRs];
  if (x_d_pu > 0.0 && x_q_pu > 0.0) {
    m.x_d_pu = x_d_pu;
    m.x_q_pu = x_q_pu;
  }
  return m;
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
  const Mat2 steady = steady_state_gradients(model, n_pu, state_.predictor.i_hat_pu);
  Mat2 g = state_.predictor.gradient;
  if (config_.gradient_psi_m == GradientForm::kSteadyState) g.col(kPsiM) = steady.col(kPsiM);
  if (config_.gradient_r_s == GradientForm::kSteadyState) g.col(kRs) = steady.col(kRs);
  return g;
}

EstimatorOutput RpemEstimator::step(const EstimatorSample& sample) noexcept {
  EstimatorOutput out;
  out.theta_pu = state_.theta_pu;
  out.flags = state_.frozen ? step_flag::kFrozen : 0;

  if (!finite(sample)) {
    state_.synchronized = false;
    state_.epsilon_valid = false;
    out.code = StepCode::kRejectedNonFinite;
    return out;
  }
  const auto& iv = sample.interval;
  const MachinePu model = model_for(sample.x_d_pu, sample.x_q_pu);
  if (sample.resync || !state_.synchronized || !(iv.dt_s > 0.0) || iv.dt_s > config_.max_sample_interval_s) {
    synchronize(sample, model);
    out.i_hat_pu = state_.predictor.i_hat_pu;
    out.code = StepCode::kSynchronized;
    return out;
  }

  // Saturation extensions give each sample its own inductances (two divisions); else the cached ones.
  const PredictorCoefficients coefficients =
      sample.x_d_pu > 0.0 ? PredictorCoefficients::of(model, config_.omega_n_rad_s) : coefficients_;
  // With steady-state forms for both parameters the dynamic gradients would be computed for nothing.
  const bool dynamic = config_.gradient_psi_m == GradientForm::kDynamic || config_.gradient_r_s == GradientForm::kDynamic;
  predict(model, coefficients, config_.discretization, iv, state_.predictor,
          dynamic ? Gradients::kAdvance : Gradients::kSkip);
  const Vec2& i_hat = state_.predictor.i_hat_pu;
  if (!i_hat.allFinite() || i_hat.lpNorm<Eigen::Infinity>() > config_.max_predicted_current_pu ||
      !state_.predictor.gradient.allFinite()) {
    state_.epsilon_valid = false;
    synchronize(sample, model);
    out.i_hat_pu = state_.predictor.i_hat_pu;
    out.code = StepCode::kPredictorDiverged;
    return out;
  }

  out.i_hat_pu = i_hat;
  out.epsilon_pu = sample.i_meas_pu - i_hat;
  state_.last_epsilon_pu = out.epsilon_pu;
  state_.epsilon_valid = true;
  out.gradient = select_gradient(model, iv.n_end_pu);

  const double factor = iv.dt_s * inverse_nominal_period_;
  const GainSequences& seq = config_.gains[static_cast<std::size_t>(config_.algorithm)];
  update(model, iv.n_end_pu, i_hat, scaled(seq.hessian, factor), scaled(seq.gain, factor), out);
  return out;
}

EstimatorOutput RpemEstimator::step_steady_state(const SteadyStateSample& sample,
                                                 const GainSequences& rates_per_s) noexcept {
  EstimatorOutput out;
  out.theta_pu = state_.theta_pu;
  out.flags = state_.frozen ? step_flag::kFrozen : 0;
  if (!finite(sample)) {
    state_.epsilon_valid = false;
    out.code = StepCode::kRejectedNonFinite;
    return out;
  }
  const MachinePu model = model_for(sample.x_d_pu, sample.x_q_pu);
  // The steady-state prediction of §1 with the current estimates; D ≥ r̂s² > 0 inside D_M.
  out.i_hat_pu = steady_state_current(model, sample.n_pu, sample.u_pu);
  if (!out.i_hat_pu.allFinite() || out.i_hat_pu.lpNorm<Eigen::Infinity>() > config_.max_predicted_current_pu) {
    state_.epsilon_valid = false;
    out.code = StepCode::kPredictorDiverged;  // a voltage no machine near the model answers; no update
    return out;
  }
  out.epsilon_pu = sample.i_meas_pu - out.i_hat_pu;
  state_.predictor.i_hat_pu = out.i_hat_pu;
  state_.last_epsilon_pu = out.epsilon_pu;
  state_.epsilon_valid = true;
  state_.synchronized = true;
  if (sample.resync || !(sample.dt_s > 0.0)) {
    out.code = StepCode::kSynchronized;
    return out;
  }
  out.gradient = steady_state_gradients(model, sample.n_gradient_pu, sample.i_gradient_pu);
  update(model, sample.n_pu, sample.i_gradient_pu, per_interval(rates_per_s.hessian, sample.dt_s),
         per_interval(rates_per_s.gain, sample.dt_s), out);
  return out;
}

void RpemEstimator::update(const MachinePu& model, double n_pu, const Vec2& i_gain_pu, const Vec2& gamma_r,
                           const Vec2& gamma_l, EstimatorOutput& out) noexcept {
  // eq:GainSchedule decides which parameters may move in this sample.
  Schedule active = schedule(config_.scheduler, n_pu);
  active.psi_m = active.psi_m && config_.adapt_psi_m && !state_.frozen;
  active.r_s = active.r_s && config_.adapt_r_s && !state_.frozen;

  GainOutput gain;
  switch (config_.algorithm) {
    case Algorithm::kSga:
      gain = sga_gain(out.gradient, gamma_r, gamma_l, config_.floors, state_.sga_hessian_pu);
      break;
    case Algorithm::kGna:
      gain = gna_gain(out.gradient, gna_hessian_sequence(active, gamma_r), gamma_l, config_.floors,
                      state_.gna_hessian_pu);
      break;
    case Algorithm::kPhyInt:
      gain = phyint_gain(model, n_pu, i_gain_pu, gamma_l, config_.floors);
      break;
  }
  if (gain.flags & gain_flag::kFloored) out.flags |= step_flag::kGainFloored;
  if (gain.flags & gain_flag::kPseudoInverse) out.flags |= step_flag::kPseudoInverse;

  apply_schedule(active, gain.gain);
  if (active.psi_m) out.flags |= step_flag::kPsiMActive;
  if (active.r_s) out.flags |= step_flag::kRsActive;

  state_.theta_pu += gain.gain * out.epsilon_pu;
  const std::uint8_t clamped = project(config_.bounds, state_.theta_pu);
  if (clamped & (1U << kPsiM)) out.flags |= step_flag::kProjectedPsiM;
  if (clamped & (1U << kRs)) out.flags |= step_flag::kProjectedRs;

  out.gain = gain.gain;
  out.theta_pu = state_.theta_pu;
  out.code = StepCode::kAdapted;
}

}  // namespace rpem::core
