#include "rpem/daemon/loop_thread.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <variant>

#include "rpem/core/assert.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/realtime.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;

constexpr std::array<CounterRow<LoopCounters>, 12> kLoopRows{{
    {&LoopCounters::samples, &Diag::samples},
    {&LoopCounters::resyncs, &Diag::resyncs},
    {&LoopCounters::rejected_non_finite, &Diag::rejected_non_finite},
    {&LoopCounters::rejected_implausible, &Diag::rejected_implausible},
    {&LoopCounters::wrong_kind, &Diag::samples_wrong_kind},
    {&LoopCounters::predictor_resets, &Diag::predictor_resets},
    {&LoopCounters::projections, &Diag::projections},
    {&LoopCounters::output_queue_drops, &Diag::output_queue_drops},
    {&LoopCounters::commands_applied, &Diag::commands_applied},
    {&LoopCounters::command_sequence_errors, &Diag::command_sequence_errors},
    {&LoopCounters::config_reloads, &Diag::config_reloads},
    {&LoopCounters::outliers, &Diag::outliers},
}};
/// The field of each regime's count, in core::kRegimes' order.
constexpr std::array<DiagnosticsCount, core::kRegimeCount> kRegimeFields{
    &Diag::regime_excites_both, &Diag::regime_excites_psi_m, &Diag::regime_excites_r_s, &Diag::regime_unexcited,
    &Diag::regime_transient,    &Diag::regime_not_locked,    &Diag::regime_bridge_off,  &Diag::regime_invalid};
static_assert(kLoopRows.size() + kRegimeFields.size() + 4 <= DiagnosticsRows::kMaxCounts);

std::int64_t interval_ns(double rate_Hz) noexcept {
  return rate_Hz > 0.0 ? static_cast<std::int64_t>(1e9 / rate_Hz) : INT64_MAX / 4;
}

/// Whether a sample of either kind holds only values within `m` (no std::visit: no bad_variant_access to throw).
bool within(const SourceSample& s, const core::PlausibleMagnitudes& m) noexcept {
  if (const auto* d = std::get_if<core::DriveSample>(&s)) return core::within(*d, m);
  if (const auto* a = std::get_if<core::AveragedSample>(&s)) return core::within(*a, m);
  return false;
}

/// estimate_t's t_*_source code of a core::ThermalSource: its number, which is the .lcm's SOURCE_* constant.
constexpr std::int8_t source_code(core::ThermalSource s) noexcept { return static_cast<std::int8_t>(s); }
static_assert(source_code(core::ThermalSource::none) == mirror::estimate_t::SOURCE_NONE &&
              source_code(core::ThermalSource::observed) == mirror::estimate_t::SOURCE_OBSERVED &&
              source_code(core::ThermalSource::predicted) == mirror::estimate_t::SOURCE_PREDICTED);

}  // namespace

LoopThread::LoopThread(const DaemonConfig& config, Queues queues)
    : live_(config.live),
      loop_config_(config.fixed.loop),
      queues_(std::move(queues)),
      plausible_(core::machine_plausible(config.live.machine.machine.rated)),
      estimator_(SourceCatalogue::sample_kind(config.fixed.source), config.live.machine.machine,
                 config.live.machine.estimator),
      validity_(config.live.validity, config.fixed.lcm.estimate_rate_Hz),
      thermal_(config.live.thermal, core::PerUnitBase::from_rated(config.live.machine.machine.rated),
               config.live.machine.machine),
      timer_(config.fixed.loop),
      estimate_interval_ns_(interval_ns(config.fixed.lcm.estimate_rate_Hz)),
      measurement_interval_ns_(interval_ns(config.fixed.lcm.measurement_rate_Hz)),
      stats_interval_ns_(interval_ns(config.fixed.lcm.diagnostics_rate_Hz)) {}

void LoopThread::seed(const std::optional<SeedValue>& psi_m, const std::optional<SeedValue>& r_s, std::int64_t now_ns) {
  estimator_.set_estimates(psi_m ? psi_m->value : estimator_.psi_m_Wb(), r_s ? r_s->value : estimator_.r_s_Ohm());
  auto keep = [&](int j, const SeedValue& s) {
    validity_.seed(j, s.age_s, now_ns);
    has_good_[j] = true;
    good_[j] = s.value;
    good_ns_[j] = now_ns - static_cast<std::int64_t>(std::max(0.0, s.age_s) * 1e9);
  };
  if (psi_m) keep(core::kPsiM, *psi_m);
  if (r_s) keep(core::kRs, *r_s);
}

bool LoopThread::resume_thermal(const core::ThermalSnapshot& saved, double gap_s) noexcept {
  return live_.thermal_active && thermal_.resume(saved, gap_s);
}

void LoopThread::push(const Report& r) noexcept {
  if (!queues_.reports.push(r)) ++counters_.output_queue_drops;
}

void LoopThread::apply(const Command& c) noexcept {
  switch (c.kind) {
    case Command::Kind::kReset:
      estimator_.reset();
      validity_.restart();
      thermal_.restart_observations();
      break;
    case Command::Kind::kFreeze:
      estimator_.set_frozen(true);
      break;
    case Command::Kind::kUnfreeze:
      estimator_.set_frozen(false);
      break;
    case Command::Kind::kSetValues:  // new initial values: identification starts over from them
      estimator_.set_estimates(c.psi_m_Wb, c.r_s_Ohm);
      validity_.restart();
      thermal_.restart_observations();
      break;
    case Command::Kind::kReconfigure:
      live_ = c.live;
      plausible_ = core::machine_plausible(live_.machine.machine.rated);
      estimator_.reconfigure(live_.machine.machine, live_.machine.estimator);
      validity_.reconfigure(live_.validity);
      // The temperatures and their covariance are kept (a new network starts from the old one's state).
      thermal_.reconfigure(live_.thermal, core::PerUnitBase::from_rated(live_.machine.machine.rated), live_.machine.machine);
      ++counters_.config_reloads;
      break;
  }
  if (c.seq > 0) {
    // Counted where assertions are off: the control thread admits commands in increasing order only.
    RPEM_ASSERT(c.seq > last_applied_seq_, "commands arrive in the order the control thread admitted them");
    if (c.seq <= last_applied_seq_) ++counters_.command_sequence_errors;
    last_applied_seq_ = c.seq;
    ++counters_.commands_applied;
  }
}

void LoopThread::resynchronize() noexcept {
  // An averaged chain's unjudged last window is taken back (§13): by all who counted it, as for
  // Estimate::retracted_previous in step().
  if (!estimator_.resynchronize()) return;
  validity_.retract_last();
  if (live_.thermal_active) thermal_.retract_last();
}

void LoopThread::step(const SourceSample& s, std::int64_t now_ns) noexcept {
  if (!within(s, plausible_)) {
    ++counters_.rejected_implausible;
    resynchronize();  // the next sample does not continue across the one left out
    return;
  }
  double dt_s = 0.0;
  if (!estimator_.step(s, last_, dt_s, last_sample_)) {
    ++counters_.wrong_kind;
    return;
  }
  ++counters_.samples;
  winding_sensor_.on_sample(last_sample_.t_winding_sensor_C, last_sample_.t_ns);
  drive_sensor_.on_sample(last_sample_.t_drive_sensor_C, last_sample_.t_ns);
  coolant_sensor_.on_sample(last_sample_.t_coolant_sensor_C, last_sample_.t_ns);
  const core::EstimatorOutput& d = last_.detail;
  switch (d.code) {
    case core::StepCode::kSynchronized:
      ++counters_.resyncs;
      break;
    case core::StepCode::kRejectedNonFinite:
      ++counters_.rejected_non_finite;
      break;
    case core::StepCode::kPredictorDiverged:
      ++counters_.predictor_resets;
      break;
    case core::StepCode::kOutlier:
      ++counters_.outliers;
      break;
    case core::StepCode::kExcluded:  // counted by its regime below
      break;
    case core::StepCode::kAdapted:
      eps2_d_ += last_.epsilon_A[0] * last_.epsilon_A[0];
      eps2_q_ += last_.epsilon_A[1] * last_.epsilon_A[1];
      ++eps_n_;
      break;
  }
  counters_.regimes.add(last_.regime);
  if (d.flags & (core::step_flag::kProjectedPsiM | core::step_flag::kProjectedRs)) ++counters_.projections;
  if (last_.retracted_previous) validity_.retract_last();  // the previous sample's adaptation, taken back
  validity_.on_sample(d.flags, dt_s, now_ns);
  if (live_.thermal_active) {
    core::ThermalSample t;
    t.dt_s = dt_s;
    t.winding_sensor_C = last_sample_.t_winding_sensor_C;  // NaN: none (the filter uses it if configured)
    t.coolant_C = last_sample_.t_coolant_sensor_C;         // NaN: none (the newest reading holds, else the configured)
    thermal_.step(last_, t);
  }
}

void LoopThread::report_measurement() noexcept {
  const SampleSummary& s = last_sample_;
  MeasurementReport m;
  m.utime = core::unix_us();
  m.sample_time_us = s.t_ns / 1000;
  m.theta_el_rad = s.theta_el_rad;
  m.omega_el_rad_s = s.omega_el_rad_s;
  m.u_dc_V = s.u_dc_V;
  m.i_d_A = last_.i_meas_A[0];
  m.i_q_A = last_.i_meas_A[1];
  m.i_hat_d_A = last_.i_hat_A[0];
  m.i_hat_q_A = last_.i_hat_A[1];
  m.epsilon_d_A = last_.epsilon_A[0];
  m.epsilon_q_A = last_.epsilon_A[1];
  m.t_winding_sensor_C = winding_sensor_.value_C();
  m.t_winding_sensor_age_s = winding_sensor_.age_s(s.t_ns);
  m.t_drive_sensor_C = drive_sensor_.value_C();
  m.t_drive_sensor_age_s = drive_sensor_.age_s(s.t_ns);
  m.t_coolant_sensor_C = coolant_sensor_.value_C();
  m.t_coolant_sensor_age_s = coolant_sensor_.age_s(s.t_ns);
  push(m);
}

void LoopThread::report_estimate(std::int64_t now_ns) noexcept {
  EstimateReport r;
  r.utime = core::unix_us();
  r.sample_time_us = last_sample_.t_ns / 1000;
  r.newest_rx_ns = last_sample_.rx_ns;
  r.samples = counters_.samples;
  r.psi_m_Wb = estimator_.psi_m_Wb();
  r.r_s_Ohm = estimator_.r_s_Ohm();
  r.psi_m_pu = estimator_.core().state().theta_pu[core::kPsiM];
  r.r_s_pu = estimator_.core().state().theta_pu[core::kRs];
  const TemperatureModel& t = live_.temperature;
  r.t_winding_C = t.r_s.temperature_C(r.r_s_Ohm);
  r.t_magnet_C = t.psi_m.temperature_C(r.psi_m_Wb);
  r.speed_pu = last_.speed_pu;
  r.frozen = estimator_.core().state().frozen;
  r.state = static_cast<std::int8_t>(state_);
  r.algorithm = live_.machine.estimator.algorithm;

  const ValidityTracker::Status psi = validity_.report(core::kPsiM, r.psi_m_Wb, now_ns);
  const ValidityTracker::Status rs = validity_.report(core::kRs, r.r_s_Ohm, now_ns);
  r.psi_m_adapting = psi.adapting;
  r.r_s_adapting = rs.adapting;
  r.psi_m_valid = psi.valid;
  r.r_s_valid = rs.valid;
  r.psi_m_converged = psi.converged;
  r.r_s_converged = rs.converged;
  r.psi_m_age_s = psi.age_s;
  r.r_s_age_s = rs.age_s;
  const bool good[2] = {psi.good, rs.good};
  const double value[2] = {r.psi_m_Wb, r.r_s_Ohm};
  for (int j = 0; j < 2; ++j) {
    if (!good[j]) continue;
    has_good_[j] = true;
    good_[j] = value[j];
    good_ns_[j] = now_ns;
  }
  r.has_good_psi_m = has_good_[core::kPsiM];
  r.good_psi_m_Wb = good_[core::kPsiM];
  r.good_psi_m_age_s = core::to_seconds(now_ns - good_ns_[core::kPsiM]);
  report_thermal(r);
  r.has_good_r_s = has_good_[core::kRs];
  r.good_r_s_Ohm = good_[core::kRs];
  r.good_r_s_age_s = core::to_seconds(now_ns - good_ns_[core::kRs]);
  push(r);
}

void LoopThread::report_thermal(EstimateReport& r) const noexcept {
  const core::ThermalEstimate& e = thermal_.estimate();
  r.thermal_active = live_.thermal_active && e.started;
  const std::int64_t t_ns = last_sample_.t_ns;
  const core::ThermalNodeReport m = core::report_node(e, r.thermal_active ? e.magnet : -1, t_ns);
  const core::ThermalNodeReport w = core::report_node(e, r.thermal_active ? e.winding : -1, t_ns);
  r.t_magnet_fused_C = m.t_C;
  r.t_magnet_fused_sd_C = m.sd_K;
  r.t_magnet_source = source_code(m.source);
  r.t_magnet_observed_age_s = m.observed_age_s;
  r.t_winding_fused_C = w.t_C;
  r.t_winding_fused_sd_C = w.sd_K;
  r.t_winding_source = source_code(w.source);
  r.t_winding_observed_age_s = w.observed_age_s;
  r.thermal = r.thermal_active ? thermal_.snapshot() : core::ThermalSnapshot{};
  r.thermal_start_untested_by_sensor =
      r.thermal_active && e.start_assumed_soaked && live_.thermal.winding_sensor_sigma_K > 0.0;
}

void LoopThread::report_stats() noexcept {
  LoopStatsReport r;
  r.utime_us = core::unix_us();
  r.state = state_;
  r.input_queue_depth = static_cast<std::int32_t>(queues_.samples.size());
  r.rows.set_all(kLoopRows, counters_);
  for (std::size_t k = 0; k < core::kRegimeCount; ++k) {
    r.rows.set(kRegimeFields[k], static_cast<std::int64_t>(counters_.regimes.n[k]));
  }
  r.rows.set(&Diag::r_s_on_assumed_frame, static_cast<std::int64_t>(counters_.regimes.r_s_on_assumed_frame));
  r.rows.set(&Diag::thermal_readings_held, thermal_.estimate().winding_readings_held);
  timer_.report(r.rows);
  const double n = eps_n_ > 0 ? static_cast<double>(eps_n_) : 1.0;
  r.rows.set(&Diag::epsilon_rms_d_A, std::sqrt(eps2_d_ / n));
  r.rows.set(&Diag::epsilon_rms_q_A, std::sqrt(eps2_q_ / n));
  r.rows.set(&Diag::gain_norm, last_.detail.gain.norm());
  const core::EstimatorState& state = estimator_.core().state();
  r.rows.set(&Diag::hessian_sga_psi_m_pu, state.sga_hessian_pu[core::kPsiM]);
  r.rows.set(&Diag::hessian_sga_r_s_pu, state.sga_hessian_pu[core::kRs]);
  r.rows.set(&Diag::hessian_gna_det_pu, core::det2(state.gna_hessian_pu));
  push(r);
  eps2_d_ = eps2_q_ = 0.0;
  eps_n_ = 0;
}

void LoopThread::process(std::int64_t now_ns) noexcept {
  Command c;
  while (queues_.commands.pop(c)) apply(c);

  SourceSample s;
  bool any = false;
  while (queues_.samples.pop(s)) {
    step(s, now_ns);
    any = true;
    if (now_ns >= next_measurement_ns_) {
      next_measurement_ns_ = now_ns + measurement_interval_ns_;
      report_measurement();
    }
  }
  if (any) {
    last_sample_mono_ns_ = now_ns;
    state_ = DaemonState::kRunning;
  } else if (state_ == DaemonState::kRunning &&
             now_ns - last_sample_mono_ns_ > static_cast<std::int64_t>(loop_config_.stale_timeout_s * 1e9)) {
    // No samples: hold the estimates, flag them, and start over from the next sample.
    state_ = DaemonState::kStale;
    resynchronize();
    validity_.hold();
  }
  if (now_ns >= next_estimate_ns_) {
    next_estimate_ns_ = now_ns + estimate_interval_ns_;
    report_estimate(now_ns);
  }
  if (now_ns >= next_stats_ns_) {
    next_stats_ns_ = now_ns + stats_interval_ns_;
    report_stats();
  }
}

void LoopThread::run(const std::atomic<bool>& stop) {
  name_thread("rpemd-loop");
  if (loop_config_.realtime != RealtimeMode::kOff) setup_problems_ = apply_thread_policy(loop_config_.thread);
  prefault_stack(std::size_t{256} * 1024);
  const std::int64_t start = timer_.start();
  next_estimate_ns_ = next_measurement_ns_ = next_stats_ns_ = start;
  started_.store(true, std::memory_order_release);
  while (!stop.load(std::memory_order_relaxed)) {
    const std::int64_t woke = timer_.wait();
    process(woke);
    timer_.finish(woke);
  }
  state_ = DaemonState::kStopping;
  report_estimate(core::now_ns(CLOCK_MONOTONIC));
}

}  // namespace rpem::daemon
