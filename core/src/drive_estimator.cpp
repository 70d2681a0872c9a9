#include "rpem/core/drive_estimator.hpp"

#include <algorithm>

#include "rpem/core/frames.hpp"

namespace rpem::core {

DriveEstimator::DriveEstimator(const MachineSi& machine, const EstimatorSettings& settings) noexcept
    : base_(PerUnitBase::from_rated(machine.rated)),
      conditioner_(base_, to_pu(base_, machine), settings.extensions),
      core_(make_estimator_config(base_, machine, settings)),
      regimes_(make_regime_config(base_, machine, settings)) {
  configure(settings);
  point_gains_.start(rates_per_s_, settings.nominal_sample_period_s);
}

void DriveEstimator::configure(const EstimatorSettings& settings) noexcept {
  rates_per_s_ = averaged_rates_per_s(settings)[static_cast<std::size_t>(settings.algorithm)];
  sparse_after_s_ = std::max(settings.max_sample_interval_s, settings.max_gap_carry_s);
  classify_ = settings.regimes.enabled;
  // RpemEstimator's per-sample γ_L = γ_0·Δt/T_samp.
  dense_rates_per_s_ = settings.gains[static_cast<std::size_t>(settings.algorithm)].gain / settings.nominal_sample_period_s;
  regimes_.set_gain_rates(dense_rates_per_s_);
  inv_voltage_sq_ = 1.0 / (base_.voltage_V * base_.voltage_V);
}

double DriveEstimator::reported_voltage_sq_pu(const DriveSample& sample) const noexcept {
  // |u| is the same in every amplitude-invariant frame.
  const double u_sq =
      sample.voltage_frame == Frame::kAbc ? clarke(sample.u_V).squaredNorm() : sample.u_V.head<2>().squaredNorm();
  return u_sq * inv_voltage_sq_;
}

Estimate DriveEstimator::estimate(const DriveSample& sample, const EstimatorOutput& detail, const Vec2& i_meas_pu,
                                  double n_pu, Classification regime) const noexcept {
  // Every member given: a record made with some members left to their defaults was zero-filled whole
  // first (224 bytes by `rep stos`, whose start-up cost was a tenth of the step).
  return {.t_ns = sample.t_ns,
          .psi_m_Wb = base_.flux_Wb_of(detail.theta_pu[kPsiM]),
          .r_s_Ohm = base_.resistance_Ohm_of(detail.theta_pu[kRs]),
          .epsilon_A = detail.epsilon_pu * base_.current_A,
          .i_hat_A = detail.i_hat_pu * base_.current_A,
          .i_meas_A = i_meas_pu * base_.current_A,
          .speed_pu = n_pu,
          .detail = detail,
          .regime = regime};
}

[[gnu::flatten]] Estimate DriveEstimator::step(const DriveSample& sample) noexcept {
  const EstimatorSample conditioned = conditioner_.condition(sample);
  const PredictorInterval& iv = conditioned.interval;
  if (iv.dt_s > sparse_after_s_ && !conditioned.resync) [[unlikely]]
    return step_sparse(sample, conditioned);

  if (!classify_) [[unlikely]] {
    const EstimatorOutput detail = core_.step(conditioned);
    return estimate(sample, detail, conditioned.i_meas_pu, iv.n_end_pu, kUnclassified);
  }
  Classification regime;
  const bool short_loss =
      conditioned.resync && regimes_.started() && iv.dt_s > 0.0 && iv.dt_s <= core_.config().max_sample_interval_s;
  if (short_loss) [[unlikely]] {
    // Samples lost on the way (the source saw a gap) but the stream goes on within the predictor's interval:
    // the open block spans the loss and its classification holds (the estimator resynchronises on this one).
    regime = regimes_.held();
  } else if (conditioned.resync || !(iv.dt_s <= core_.config().max_sample_interval_s)) [[unlikely]] {
    // A new chain: the voltage that acted before this sample is unknown; its own command stands in.
    RegimeInput in;
    in.timing = SampleTiming::kFirst;
    in.t_ns = sample.t_ns;
    in.u_pu = conditioner_.steady_state(sample).u_pu;
    in.i_pu = conditioned.i_meas_pu;
    in.n_pu = iv.n_end_pu;
    in.u_reported_sq_pu = reported_voltage_sq_pu(sample);
    in.weight = (dense_rates_per_s_ * iv.dt_s).cwiseMin(1.0);  // γ_L as RpemEstimator scales it
    regime = regimes_.step(in);
  } else {
    // The interval's mean voltage (trapezoidal).
    regime = regimes_.step_dense(sample.t_ns, 0.5 * (iv.u_start_pu + iv.u_end_pu), conditioned.i_meas_pu, iv.n_end_pu,
                                 reported_voltage_sq_pu(sample));
  }
  const RegimeNoise& noise = regimes_.noise();
  const Admission admission{!regime.excluded(), regime.excites_psi_m(), regime.excites_r_s(), true, noise.u_sq, noise.i_sq,
                            noise.n_sq};
  const EstimatorOutput detail = core_.step(conditioned, admission);
  return estimate(sample, detail, conditioned.i_meas_pu, iv.n_end_pu, regime);
}

Estimate DriveEstimator::step_sparse(const DriveSample& sample, const EstimatorSample& conditioned) noexcept {
  const SteadyStateInputs own = conditioner_.steady_state(sample);
  SteadyStateSample s;
  s.dt_s = conditioned.interval.dt_s;
  s.u_pu = own.u_pu;
  s.i_meas_pu = own.i_pu;
  s.n_pu = own.n_pu;
  // Its own operating point: the neighbours are too far to stand in for it as an instrument.
  s.i_gradient_pu = own.i_pu;
  s.n_gradient_pu = own.n_pu;
  s.x_d_pu = own.x_d_pu;
  s.x_q_pu = own.x_q_pu;
  const GainSequences gains = point_gains_.at(rates_per_s_, sample.t_ns);
  if (!classify_) [[unlikely]] {
    const EstimatorOutput detail = core_.step_steady_state(s, gains.hessian, gains.gain, Admission{});
    if (detail.code == StepCode::kAdapted) point_gains_.count(gains, sample.t_ns);
    return estimate(sample, detail, own.i_pu, own.n_pu, kUnclassified);
  }

  RegimeInput in;
  in.timing = SampleTiming::kStandalone;
  in.t_ns = sample.t_ns;
  in.u_pu = own.u_pu;
  in.i_pu = own.i_pu;
  in.n_pu = own.n_pu;
  in.u_reported_sq_pu = reported_voltage_sq_pu(sample);
  in.weight = gains.gain;
  const Classification regime = regimes_.step(in);
  const RegimeNoise& noise = regimes_.noise();
  const Admission admission{!regime.excluded(), regime.excites_psi_m(), regime.excites_r_s(), true, noise.u_sq, noise.i_sq,
                            noise.n_sq};
  const EstimatorOutput detail = core_.step_steady_state(s, gains.hessian, gains.gain, admission);
  if (detail.code == StepCode::kAdapted) point_gains_.count(gains, sample.t_ns);
  return estimate(sample, detail, own.i_pu, own.n_pu, regime);
}

void DriveEstimator::reset() noexcept {
  conditioner_.reset();
  core_.reset();
  regimes_.reset();
  point_gains_.start(rates_per_s_, core_.config().nominal_sample_period_s);
}

bool DriveEstimator::resynchronize() noexcept {
  conditioner_.reset();
  core_.resynchronize();
  regimes_.break_chain();
  return false;  // a dense sample is never taken back
}

void DriveEstimator::set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept {
  core_.set_theta({base_.flux_pu(psi_m_Wb), base_.resistance_pu(r_s_Ohm)});
}

void DriveEstimator::reconfigure(const MachineSi& machine, const EstimatorSettings& settings) noexcept {
  base_ = PerUnitBase::from_rated(machine.rated);
  conditioner_.reconfigure(base_, to_pu(base_, machine), settings.extensions);
  core_.reconfigure(make_estimator_config(base_, machine, settings));
  regimes_.reconfigure(make_regime_config(base_, machine, settings));
  configure(settings);
}

double DriveEstimator::psi_m_Wb() const noexcept { return base_.flux_Wb_of(core_.state().theta_pu[kPsiM]); }
double DriveEstimator::r_s_Ohm() const noexcept { return base_.resistance_Ohm_of(core_.state().theta_pu[kRs]); }

}  // namespace rpem::core
