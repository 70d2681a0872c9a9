#include "rpem/daemon/estimator_loop.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <ctime>

#include "rpem/daemon/realtime.hpp"

namespace rpem::daemon {
namespace {

std::int64_t clock_ns(clockid_t c) noexcept {
  timespec ts{};
  clock_gettime(c, &ts);  // vDSO: no system call
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t interval_ns(double rate_Hz) noexcept {
  return rate_Hz > 0.0 ? static_cast<std::int64_t>(1e9 / rate_Hz) : INT64_MAX / 4;
}

}  // namespace

EstimatorLoop::EstimatorLoop(const DaemonConfig& config, SpscQueue<core::DriveSample>& input,
                             SpscQueue<Command>& commands, SpscQueue<Report>& output)
    : config_(config),
      input_(input),
      commands_(commands),
      output_(output),
      estimator_(config.machine.machine, config.machine.estimator),
      period_ns_(static_cast<std::int64_t>(config.loop_period_s * 1e9)),
      wake_ahead_ns_(static_cast<std::int64_t>(config.loop_wake_ahead_s * 1e9)),
      wake_ahead_calibration_periods_(config.loop_wake_ahead_auto
                                          ? std::max<std::int64_t>(1, std::llround(1.0 / config.loop_period_s))
                                          : 0),
      wake_ahead_published_ns_(config.loop_wake_ahead_auto ? -1 : wake_ahead_ns_),
      estimate_interval_ns_(interval_ns(config.estimate_rate_Hz)),
      measurement_interval_ns_(interval_ns(config.measurement_rate_Hz)),
      stats_interval_ns_(interval_ns(config.diagnostics_rate_Hz)) {
  ring_size_ = std::clamp(static_cast<int>(config.validity.convergence_window_s * config.estimate_rate_Hz), 2, 64);
}

void EstimatorLoop::seed(const std::optional<double>& psi_m_Wb, const std::optional<double>& r_s_Ohm) {
  estimator_.set_estimates(psi_m_Wb.value_or(estimator_.psi_m_Wb()), r_s_Ohm.value_or(estimator_.r_s_Ohm()));
  if (psi_m_Wb) {
    has_good_psi_ = true;
    good_psi_ = *psi_m_Wb;
  }
  if (r_s_Ohm) {
    has_good_rs_ = true;
    good_rs_ = *r_s_Ohm;
    r_s_valid_ = true;  // a persisted converged r_s is valid until a reset
  }
}

void EstimatorLoop::push(const Report& r) noexcept {
  if (!output_.push(r)) ++output_drops_;
}

void EstimatorLoop::apply(const Command& c) noexcept {
  switch (c.kind) {
    case Command::Kind::kReset:
      estimator_.reset();
      r_s_valid_ = false;
      r_s_adapted_s_ = psi_m_adapted_s_ = 0.0;
      ring_count_ = 0;
      break;
    case Command::Kind::kFreeze:
      estimator_.set_frozen(true);
      break;
    case Command::Kind::kUnfreeze:
      estimator_.set_frozen(false);
      break;
    case Command::Kind::kSetValues:
      estimator_.set_estimates(c.psi_m_Wb, c.r_s_Ohm);
      ring_count_ = 0;
      break;
    case Command::Kind::kReconfigure:
      estimator_.reconfigure(c.machine, c.settings);
      config_.machine.machine = c.machine;
      config_.machine.estimator = c.settings;
      config_.temperature = c.temperature;
      config_.validity = c.validity;
      ++config_reloads_;
      break;
  }
  if (c.seq > 0) {
    last_seq_ = c.seq;
    last_result_ = CommandResult::kApplied;
    ++commands_applied_;
  }
}

void EstimatorLoop::step(const core::DriveSample& s) noexcept {
  last_ = estimator_.step(s);
  last_sample_ = s;
  ++samples_;
  const auto& d = last_.detail;
  switch (d.code) {
    case core::StepCode::kSynchronized:
      ++resyncs_;
      break;
    case core::StepCode::kRejectedNonFinite:
      ++rejected_;
      break;
    case core::StepCode::kPredictorDiverged:
      ++predictor_resets_;
      break;
    case core::StepCode::kAdapted:
      eps2_d_ += last_.epsilon_A[0] * last_.epsilon_A[0];
      eps2_q_ += last_.epsilon_A[1] * last_.epsilon_A[1];
      ++eps_n_;
      break;
  }
  if (d.flags & (core::step_flag::kProjectedPsiM | core::step_flag::kProjectedRs)) ++projections_;
  const double dt = estimator_.core().config().nominal_sample_period_s;
  if (d.flags & core::step_flag::kRsActive) r_s_adapted_s_ += dt;
  if (r_s_adapted_s_ >= config_.validity.r_s_after_s) r_s_valid_ = true;
  psi_m_adapted_s_ = (d.flags & core::step_flag::kPsiMActive) ? psi_m_adapted_s_ + dt : 0.0;
}

bool EstimatorLoop::converged(const std::array<double, 64>& ring, int count) const noexcept {
  if (count < ring_size_) return false;
  double lo = ring[0], hi = ring[0];
  for (int k = 1; k < ring_size_; ++k) {
    lo = std::min(lo, ring[static_cast<std::size_t>(k)]);
    hi = std::max(hi, ring[static_cast<std::size_t>(k)]);
  }
  return hi - lo <= config_.validity.convergence_band * std::abs(hi);
}

void EstimatorLoop::report_estimate(std::int64_t) noexcept {
  EstimateReport r;
  r.utime_us = clock_ns(CLOCK_REALTIME) / 1000;
  r.sample_time_us = last_sample_.t_ns / 1000;
  r.newest_rx_ns = last_sample_.rx_ns;
  r.samples = samples_;
  r.psi_m_Wb = estimator_.psi_m_Wb();
  r.r_s_Ohm = estimator_.r_s_Ohm();
  r.psi_m_pu = estimator_.core().state().theta_pu[core::kPsiM];
  r.r_s_pu = estimator_.core().state().theta_pu[core::kRs];
  const TemperatureModel& t = config_.temperature;
  r.t_winding_C = t.r_s.temperature_C(r.r_s_Ohm);
  r.t_magnet_C = t.psi_m.temperature_C(r.psi_m_Wb);
  r.speed_pu = last_.speed_pu;
  r.psi_m_adapting = last_.detail.flags & core::step_flag::kPsiMActive;
  r.r_s_adapting = last_.detail.flags & core::step_flag::kRsActive;
  r.frozen = estimator_.core().state().frozen;
  r.state = state_;
  r.algorithm = estimator_.core().config().algorithm;

  psi_ring_[static_cast<std::size_t>(ring_head_)] = r.psi_m_Wb;
  rs_ring_[static_cast<std::size_t>(ring_head_)] = r.r_s_Ohm;
  ring_head_ = (ring_head_ + 1) % ring_size_;
  ring_count_ = std::min(ring_count_ + 1, ring_size_);
  const bool live = state_ == DaemonState::kRunning;
  r.psi_m_valid = live && r.psi_m_adapting && psi_m_adapted_s_ >= config_.validity.psi_m_after_s;
  r.r_s_valid = r_s_valid_;
  r.psi_m_converged = converged(psi_ring_, ring_count_);
  r.r_s_converged = converged(rs_ring_, ring_count_);
  if (r.psi_m_valid && r.psi_m_converged) {
    has_good_psi_ = true;
    good_psi_ = r.psi_m_Wb;
  }
  if (r.r_s_valid && r.r_s_converged && r.r_s_adapting) {
    has_good_rs_ = true;
    good_rs_ = r.r_s_Ohm;
  }
  r.has_good_psi_m = has_good_psi_;
  r.good_psi_m_Wb = good_psi_;
  r.has_good_r_s = has_good_rs_;
  r.good_r_s_Ohm = good_rs_;
  push(r);
}

void EstimatorLoop::report_stats(std::int64_t) noexcept {
  LoopStatsReport r;
  r.utime_us = clock_ns(CLOCK_REALTIME) / 1000;
  r.state = state_;
  r.period_ns = period_ns_;
  r.latency_min_us = latency_.min();
  r.latency_mean_us = latency_.mean();
  r.latency_max_us = latency_.max();
  r.latency_p99_us = latency_.percentile(0.99);
  r.work_max_us = work_max_us_;
  r.overruns = overruns_;
  r.periods = periods_;
  r.samples = samples_;
  r.resyncs = resyncs_;
  r.rejected_non_finite = rejected_;
  r.predictor_resets = predictor_resets_;
  r.projections = projections_;
  const double n = eps_n_ > 0 ? static_cast<double>(eps_n_) : 1.0;
  r.eps_rms_d_A = std::sqrt(eps2_d_ / n);
  r.eps_rms_q_A = std::sqrt(eps2_q_ / n);
  r.gain_norm = last_.detail.gain.norm();
  const auto& st = estimator_.core().state();
  r.hessian_sga_psi_m = st.sga_hessian_pu[core::kPsiM];
  r.hessian_sga_r_s = st.sga_hessian_pu[core::kRs];
  r.hessian_gna_det = core::det2(st.gna_hessian_pu);
  r.input_queue_depth = static_cast<std::int32_t>(input_.size());
  r.output_queue_drops = output_drops_;
  r.commands_applied = commands_applied_;
  r.last_command_seq = last_seq_;
  r.last_command_result = last_result_;
  r.config_reloads = config_reloads_;
  push(r);
  latency_.reset();
  work_max_us_ = 0.0;
  eps2_d_ = eps2_q_ = 0.0;
  eps_n_ = 0;
}

void EstimatorLoop::process(std::int64_t now_ns) noexcept {
  Command c;
  while (commands_.pop(c)) apply(c);

  core::DriveSample s;
  bool any = false;
  while (input_.pop(s)) {
    step(s);
    any = true;
    if (now_ns >= next_measurement_ns_) {
      next_measurement_ns_ = now_ns + measurement_interval_ns_;
      MeasurementReport m;
      m.utime_us = clock_ns(CLOCK_REALTIME) / 1000;
      m.sample_time_us = s.t_ns / 1000;
      m.theta_el_rad = s.theta_el_rad;
      m.omega_el_rad_s = s.omega_el_rad_s;
      m.u_dc_V = s.u_dc_V;
      m.i_d_A = last_.i_meas_A[0];
      m.i_q_A = last_.i_meas_A[1];
      m.i_hat_d_A = last_.i_hat_A[0];
      m.i_hat_q_A = last_.i_hat_A[1];
      m.eps_d_A = last_.epsilon_A[0];
      m.eps_q_A = last_.epsilon_A[1];
      push(m);
    }
  }
  if (any) {
    last_sample_mono_ns_ = now_ns;
    if (state_ != DaemonState::kRunning) state_ = DaemonState::kRunning;
  } else if (state_ == DaemonState::kRunning &&
             now_ns - last_sample_mono_ns_ > static_cast<std::int64_t>(config_.stale_timeout_s * 1e9)) {
    // No samples: hold the estimates, flag them, and start over from the next sample.
    state_ = DaemonState::kStale;
    estimator_.resynchronize();
  }
  if (now_ns >= next_estimate_ns_) {
    next_estimate_ns_ = now_ns + estimate_interval_ns_;
    report_estimate(now_ns);
  }
  if (now_ns >= next_stats_ns_) {
    next_stats_ns_ = now_ns + stats_interval_ns_;
    report_stats(now_ns);
  }
}

void EstimatorLoop::run(std::atomic<bool>& stop) {
  name_thread("rpemd-loop");
  if (config_.realtime != RealtimeMode::kOff) setup_problems_ = apply_thread_policy(config_.loop_thread);
  prefault_stack(256 * 1024);
  std::int64_t next = clock_ns(CLOCK_MONOTONIC);
  next_estimate_ns_ = next_measurement_ns_ = next_stats_ns_ = next;
  started_.store(true, std::memory_order_release);
  while (!stop.load(std::memory_order_relaxed)) {
    next += period_ns_;
    const std::int64_t wake = next - wake_ahead_ns_;
    timespec ts{static_cast<time_t>(wake / 1'000'000'000), static_cast<long>(wake % 1'000'000'000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
    std::int64_t woke = clock_ns(CLOCK_MONOTONIC);
    while (woke < next) {  // timer anticipation (loop.wake_ahead_s): spin to the deadline
      spin_pause();
      woke = clock_ns(CLOCK_MONOTONIC);
    }
    const double late_us = 1e-3 * static_cast<double>(woke - next);
    latency_.add(late_us);
    run_latency_.add(late_us);
    process(woke);
    ++periods_;
    const std::int64_t done = clock_ns(CLOCK_MONOTONIC);
    work_max_us_ = std::max(work_max_us_, 1e-3 * static_cast<double>(done - woke));
    if (done > next + period_ns_) {
      // The next deadline has passed: count it and restart the schedule from now.
      ++overruns_;
      next = done - done % period_ns_;
    }
    if (periods_ == wake_ahead_calibration_periods_) {
      // `wake_ahead_s: auto`: anticipate by the median wake-up latency of the first second (a one-off
      // scan of the histogram's bins, a few µs).
      wake_ahead_ns_ = std::min<std::int64_t>(period_ns_ / 2, std::llround(1e3 * run_latency_.percentile(0.5)));
      wake_ahead_published_ns_.store(wake_ahead_ns_, std::memory_order_release);
    }
    heartbeat_.fetch_add(1, std::memory_order_release);
  }
  state_ = DaemonState::kStopping;
  report_estimate(clock_ns(CLOCK_MONOTONIC));
}

}  // namespace rpem::daemon
