#include "rpem/core/averaged_estimator.hpp"

#include <cmath>

#include "rpem/core/clock.hpp"
#include "rpem/core/reported_speed.hpp"
#include "rpem/core/sinc.hpp"

namespace rpem::core {
namespace {

/// Extensions that have a rotor-frame mean (per-phase current offsets and gains have none).
ModelExtensions rotor_frame_extensions(const ModelExtensions& x) noexcept {
  ModelExtensions r = x;
  r.current_offset_A.setZero();
  r.current_gain_error.setZero();
  return r;
}

DriveSample as_dq_sample(const AveragedSample& a, double staircase_below_rad_s) noexcept {
  DriveSample d;
  d.t_ns = a.t_ns;
  d.theta_el_rad = 0.0;  // dq in, dq out: the angle cancels
  d.omega_el_rad_s = window_speed_rad_s(a, staircase_below_rad_s);
  d.u_dc_V = std::isnan(a.u_dc_V) ? 0.0 : a.u_dc_V;
  d.voltage_frame = Frame::kDq;
  d.u_V = Vec3(a.u_dq_V[0], a.u_dq_V[1], 0.0);
  d.current_frame = Frame::kDq;
  d.i_A = Vec3(a.i_dq_A[0], a.i_dq_A[1], 0.0);
  return d;
}

}  // namespace

AveragedDriveEstimator::AveragedDriveEstimator(const MachineSi& machine, const EstimatorSettings& settings) noexcept
    : base_(PerUnitBase::from_rated(machine.rated)),
      conditioner_(base_, to_pu(base_, machine), rotor_frame_extensions(settings.extensions)),
      core_(make_estimator_config(base_, machine, settings)),
      classifier_(make_regime_config(base_, machine, settings)) {
  configure(settings);
  point_gains_.start(rates_per_s_[static_cast<std::size_t>(core_.config().algorithm)], settings.nominal_sample_period_s);
}

void AveragedDriveEstimator::configure(const EstimatorSettings& settings) noexcept {
  rates_per_s_ = averaged_rates_per_s(settings);
  options_ = settings.averaged;
  options_classify_ = settings.regimes.enabled;
  delay_s_ = settings.extensions.delay_s;
  staircase_below_rad_s_ = settings.regimes.hall_interpolation_speed_rad_s;
}

SteadyStateSample AveragedDriveEstimator::condition(const AveragedSample& a) noexcept {
  const SteadyStateInputs in = conditioner_.steady_state(as_dq_sample(a, staircase_below_rad_s_));
  SteadyStateSample s;
  s.u_pu = in.u_pu;
  s.i_meas_pu = in.i_pu;
  s.n_pu = in.n_pu;
  s.x_d_pu = in.x_d_pu;
  s.x_q_pu = in.x_q_pu;
  const double omega_n = base_.omega_el_rad_s;
  if (delay_s_ > 0.0) {
    // A command acting `delay` late is, in the rotor frame at constant speed, the logged one turned by −ω·delay.
    const Rotation back = Rotation::of(-s.n_pu * omega_n * delay_s_);
    s.u_pu = Vec2(back.cos * s.u_pu[0] - back.sin * s.u_pu[1], back.sin * s.u_pu[0] + back.cos * s.u_pu[1]);
  }
  if (options_.voltage_is_command && options_.control_period_s > 0.0) {
    // Reported command (§11): held over one period from the delay on, its mean in the rotor frame at the
    // sample is the command turned by −ω·(delay + T_c/2) and shortened by sinc(ω·T_c/2); the delay's turn is above.
    const double half = 0.5 * s.n_pu * omega_n * options_.control_period_s;
    const double sinc = core::sinc(half);
    const Rotation back = Rotation::of(-half);
    s.u_pu = sinc * Vec2(back.cos * s.u_pu[0] - back.sin * s.u_pu[1], back.sin * s.u_pu[0] + back.cos * s.u_pu[1]);
  }
  if (options_.control_period_s > 0.0) {
    // Sampled means (§11): ī = i_sample + c·ω·T_c²·L⁻¹·J·ū, c = (a − ½)²/2 − 1/24; in pu c·n·(ω_n·T_c)²·J·u/x.
    const double a_half = options_.current_sample_at - 0.5;
    const double wt = omega_n * options_.control_period_s;
    const double k = (0.5 * a_half * a_half - 1.0 / 24.0) * s.n_pu * wt * wt;
    s.i_meas_pu += Vec2(-k * s.u_pu[1] / s.x_d_pu, k * s.u_pu[0] / s.x_q_pu);
  }

  const std::int64_t window_ns = a.t_ns - a.t_start_ns;
  s.dt_s = has_previous_ ? to_seconds(a.t_ns - *previous_t_ns_) : 0.0;
  // How the sample continues the previous one (docs/derivations.md §13, "Contiguity"): a window is
  // adjacent when it starts where the previous one ended — not later by more than half its own length (or
  // windows were lost) — whatever its length; an instantaneous sample when it follows within
  // averaged.max_interval_s, and otherwise stands alone, a steady-state observation of its own.
  const bool follows = has_previous_ && !a.gap_before && s.dt_s > 0.0;
  if (!follows) {
    timing_ = SampleTiming::kFirst;
  } else if (window_ns > 0) {
    timing_ = 2 * (a.t_start_ns - *previous_t_ns_) <= window_ns ? SampleTiming::kContiguous : SampleTiming::kFirst;
  } else {
    timing_ = s.dt_s <= options_.max_interval_s ? SampleTiming::kContiguous : SampleTiming::kStandalone;
  }
  const bool contiguous = timing_ == SampleTiming::kContiguous;
  s.resync = timing_ == SampleTiming::kFirst;
  // The instrument: the preceding samples' operating point (this sample enters it only afterwards).
  if (!contiguous) {
    instrument_i_pu_ = s.i_meas_pu;
    instrument_n_pu_ = s.n_pu;
  }
  s.i_gradient_pu = instrument_i_pu_;
  s.n_gradient_pu = instrument_n_pu_;
  const double w = options_.instrument_time_constant_s > 0.0 && contiguous
                       ? -std::expm1(-s.dt_s / options_.instrument_time_constant_s)
                       : 1.0;
  instrument_i_pu_ += w * (s.i_meas_pu - instrument_i_pu_);
  instrument_n_pu_ += w * (s.n_pu - instrument_n_pu_);
  previous_t_ns_ = a.t_ns;
  has_previous_ = s.i_meas_pu.allFinite();
  return s;
}

Estimate AveragedDriveEstimator::step(const AveragedSample& sample) noexcept {
  SteadyStateSample s = condition(sample);
  const GainSequences& rates = rates_per_s_[static_cast<std::size_t>(core_.config().algorithm)];
  // Windows carry their length's worth of data (per_interval); instantaneous samples one observation each.
  const bool point = sample.t_ns == sample.t_start_ns;
  const GainSequences gains = point ? point_gains_.at(rates, sample.t_ns)
                                    : GainSequences{per_interval(rates.hessian, s.dt_s), per_interval(rates.gain, s.dt_s)};

  if (!options_classify_) [[unlikely]] {
    if (options_.inductive_correction && timing_ == SampleTiming::kContiguous) {
      // What the classifier would have taken: the slope between the window centres (§11).
      const double dc_s = 0.5 * to_seconds((sample.t_start_ns + sample.t_ns) - previous_centre2_ns_);
      const Vec2 di_dt = (s.i_meas_pu - previous_i_pu_) / dc_s;
      s.u_pu -= Vec2(s.x_d_pu * di_dt[0], s.x_q_pu * di_dt[1]) / base_.omega_el_rad_s;
    }
    previous_centre2_ns_ = sample.t_start_ns + sample.t_ns;
    previous_i_pu_ = s.i_meas_pu;
    judge_pending_ = false;  // without regimes no window is judged, nor retracted
    return finish(sample, s, core_.step_steady_state(s, gains.hessian, gains.gain, Admission{}), kUnclassified, point,
                  gains);
  }
  RegimeInput in;
  in.timing = timing_;
  in.t_ns = sample.t_ns;
  in.window_s = to_seconds(sample.t_ns - sample.t_start_ns);
  in.u_pu = s.u_pu;
  in.i_pu = s.i_meas_pu;
  in.n_pu = s.n_pu;
  const SpeedError speed_error = window_speed_error(sample, staircase_below_rad_s_);
  in.n_error_pu = base_.speed_pu(speed_error.error_rad_s);
  in.n_error_noise_pu = base_.speed_pu(speed_error.noise_rad_s);
  if (std::isfinite(sample.omega_el_at_reads_max_rad_s)) in.n_reach_pu = base_.speed_pu(sample.omega_el_at_reads_max_rad_s);
  in.u_reported_sq_pu = sample.u_dq_V.squaredNorm() / (base_.voltage_V * base_.voltage_V);
  in.u_reported_pu = Vec2(base_.voltage_pu(sample.u_dq_V[0]), base_.voltage_pu(sample.u_dq_V[1]));
  in.i_reported_pu = Vec2(base_.current_pu(sample.i_dq_A[0]), base_.current_pu(sample.i_dq_A[1]));
  in.weight = gains.gain;
  const Classification regime = classifier_.step(in);
  // Only a finite window continuing the chain judges the previous one (§13, "Mixed windows"): a release found inside
  // it undoes what it adapted. Any other sample (a gap, an instantaneous or a non-finite one) ends the chain with the
  // previous window unjudged, and it is undone all the same ("A chain's last window").
  const bool judges = in.window_s > 0.0 && timing_ == SampleTiming::kContiguous && regime.regime != Regime::kInvalid;
  bool retracted = false;
  if (!judges) {
    retracted = end_chain();
  } else if ((regime.bits & regime_bit::kPreviousMixed) && !core_.state().frozen) {
    retracted = judge_pending_;  // an excluded window adapted nothing: there is nothing of it to take back
    core_.retract(before_previous_);
  }
  before_previous_ = core_.adaptation();
  judge_pending_ = judges && !regime.excluded();
  if (options_.inductive_correction && timing_ == SampleTiming::kContiguous) {
    // (x/ω_n)·di/dt with di/dt from the means of consecutive windows, between their centres (§11).
    const Vec2& di_dt = classifier_.slope_pu_s();
    s.u_pu -= Vec2(s.x_d_pu * di_dt[0], s.x_q_pu * di_dt[1]) / base_.omega_el_rad_s;
  }

  const RegimeNoise noise = classifier_.noise();
  const Admission admission{!regime.excluded(), regime.excites_psi_m(), regime.excites_r_s(), true, noise.u_sq, noise.i_sq,
                            noise.n_sq};
  Estimate e = finish(sample, s, core_.step_steady_state(s, gains.hessian, gains.gain, admission), regime, point, gains);
  e.retracted_previous = retracted;
  return e;
}

Estimate AveragedDriveEstimator::finish(const AveragedSample& sample, const SteadyStateSample& s,
                                        const EstimatorOutput& detail, Classification regime, bool point,
                                        const GainSequences& gains) noexcept {
  Estimate e;
  e.t_ns = sample.t_ns;
  e.detail = detail;
  if (point && e.detail.code == StepCode::kAdapted) point_gains_.count(gains, sample.t_ns);
  e.psi_m_Wb = base_.flux_Wb_of(e.detail.theta_pu[kPsiM]);
  e.r_s_Ohm = base_.resistance_Ohm_of(e.detail.theta_pu[kRs]);
  e.epsilon_A = e.detail.epsilon_pu * base_.current_A;
  e.i_hat_A = e.detail.i_hat_pu * base_.current_A;
  e.i_meas_A = s.i_meas_pu * base_.current_A;
  e.speed_pu = s.n_pu;
  e.regime = regime;
  return e;
}

bool AveragedDriveEstimator::end_chain() noexcept {
  if (!judge_pending_) return false;
  judge_pending_ = false;
  if (core_.state().frozen) return false;  // frozen: nothing moves θ̂, a retraction neither
  const Vec2 theta_pu = core_.state().theta_pu;
  core_.retract(before_previous_);
  before_previous_ = core_.adaptation();
  unjudged_windows_ += core_.state().theta_pu != theta_pu ? 1U : 0U;
  return true;
}

void AveragedDriveEstimator::reset() noexcept {
  has_previous_ = false;
  judge_pending_ = false;
  core_.reset();
  classifier_.reset();
  before_previous_ = core_.adaptation();
  point_gains_.start(rates_per_s_[static_cast<std::size_t>(core_.config().algorithm)],
                     core_.config().nominal_sample_period_s);
}

void AveragedDriveEstimator::set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept {
  core_.set_theta({base_.flux_pu(psi_m_Wb), base_.resistance_pu(r_s_Ohm)});
  before_previous_ = core_.adaptation();  // a retraction never undoes the seed
  judge_pending_ = false;
}

void AveragedDriveEstimator::reconfigure(const MachineSi& machine, const EstimatorSettings& settings) noexcept {
  base_ = PerUnitBase::from_rated(machine.rated);
  conditioner_.reconfigure(base_, to_pu(base_, machine), rotor_frame_extensions(settings.extensions));
  core_.reconfigure(make_estimator_config(base_, machine, settings));
  // A saved adaptation is of the old bounds (θ̂ was projected onto the new ones): no retraction reaches across a reload.
  before_previous_ = core_.adaptation();
  judge_pending_ = false;
  classifier_.reconfigure(make_regime_config(base_, machine, settings));
  configure(settings);
}

double AveragedDriveEstimator::psi_m_Wb() const noexcept { return base_.flux_Wb_of(core_.state().theta_pu[kPsiM]); }
double AveragedDriveEstimator::r_s_Ohm() const noexcept { return base_.resistance_Ohm_of(core_.state().theta_pu[kRs]); }

}  // namespace rpem::core
