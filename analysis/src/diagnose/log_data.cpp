#include "rpem/analysis/diagnose/log_data.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>

#include "../median.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/sinc.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/sample_counts.hpp"

namespace rpem::analysis {
namespace {

/// Changes between neighbouring rows beyond this share of the log's range mark a row as transitional.
constexpr double kTransitionShare = 0.05;
/// Below this share of the largest current and speed a row is an idle drive.
constexpr double kIdleShare = 0.02;
/// Steady state when samples lie this many electrical time constants apart.
constexpr double kSteadyStateTimeConstants = 5.0;

/// Each sample's time since the first with the log's pauses left out (an interval longer than
/// LogData::kPauseMedianIntervals median intervals counts nothing), and the time between sessions; counts the
/// pauses into `d`.
std::vector<double> sampled_time_s(LogData& d) {
  std::vector<double> sampled(d.size(), 0.0);
  d.pauses = 0;
  d.longest_pause_s = 0.0;
  const double pause_s = LogData::kPauseMedianIntervals * d.median_dt_s;
  for (std::size_t k = 1; k < d.size(); ++k) {
    const double step_s = d.t_s(k) - d.t_s(k - 1);
    if (d.starts_session(k)) {
      sampled[k] = sampled[k - 1];
      continue;
    }
    const bool pause = d.median_dt_s > 0.0 && step_s > pause_s;
    sampled[k] = sampled[k - 1] + (pause ? 0.0 : step_s);
    if (pause) {
      ++d.pauses;
      d.longest_pause_s = std::max(d.longest_pause_s, step_s);
    }
  }
  return sampled;
}

}  // namespace

const char* to_string(ModelMode m) noexcept { return m == ModelMode::kTransient ? "transient" : "steady_state"; }

core::DriveSample LogData::replay_sample(std::size_t k) const noexcept {
  core::DriveSample s = samples.sample(k);
  const std::size_t w = static_cast<std::size_t>(speed_half_window), n = samples.size();
  if (w == 0 || k < w || k + w >= n) return s;
  // Only across a gap-free stretch; else the logged speed stays.
  for (std::size_t j = k - w + 1; j <= k + w; ++j) {
    if (samples.gap_before(j)) return s;
  }
  const double dt = core::to_seconds(samples.t_ns(k + w) - samples.t_ns(k - w));
  if (dt > 0.0) s.omega_el_rad_s = core::wrap_angle(samples.theta_el_rad(k + w) - samples.theta_el_rad(k - w)) / dt;
  return s;
}

core::Vec2 LogData::logged_i_dq_A(std::size_t k) const noexcept {
  const core::DriveSample s = samples.sample(k);
  return core::SampleConditioner::logged_current_dq_A(s, core::Rotation::of(s.theta_el_rad));
}

std::size_t LogData::used_count() const noexcept {
  std::size_t n = 0;
  for (std::size_t k = 0; k < size(); ++k) n += used(k) ? 1 : 0;
  return n;
}

std::size_t LogData::training_count() const noexcept {
  std::size_t n = 0;
  for (int b = 0; b < blocks; b += 2) {
    for (std::size_t k = block_first[static_cast<std::size_t>(b)]; k < block_first[static_cast<std::size_t>(b) + 1]; ++k)
      n += used(k) ? 1 : 0;
  }
  return n;
}

namespace {

/// Enough samples for the training and held-out blocks (2 each); else the log's fault.
void check_enough_samples(const LogData& d, const LogOptions& options) {
  const std::size_t n = d.samples.size();
  if (n < 2 * static_cast<std::size_t>(std::max(2, options.blocks))) {
    // Samples, not rows: an averaged or VESC Tool log's first row only opens the first window.
    const int blocks = std::max(2, options.blocks);
    const std::string purpose = options.samples_needed_for.empty()
                                    ? std::to_string(blocks) + " training and held-out blocks, 2 each"
                                    : options.samples_needed_for;
    throw io::DriveLogError(d.path, 0, 0, "",
                            "the log gives " + std::to_string(n) + (n == 1 ? " sample" : " samples") + "; at least " +
                                std::to_string(2 * blocks) + " are needed (" + purpose + ")");
  }
}

/// The steady-state replay's rows with nothing to fit (idle: current and speed both near zero) and those not at a
/// steady operating point (in transition: a neighbour in the same session differs), marked left out and counted.
void leave_out_idle_and_transitional(LogData& d) {
  const std::size_t n = d.samples.size();
  const double i_span = std::max(d.max_current_A, 1e-9), n_span = std::max(d.max_speed_rad_s, 1e-9);
  auto current = [&](std::size_t k) { return d.logged_i_dq_A(k).norm(); };
  auto speed = [&](std::size_t k) { return d.samples.omega_el_rad_s(k); };
  for (std::size_t k = 0; k < n; ++k) {
    if (current(k) < kIdleShare * i_span && std::abs(speed(k)) < kIdleShare * n_span) {
      d.samples.set_mark(k, sample_mark::kLeftOut, true);
      ++d.excluded_idle;
      continue;
    }
    for (std::size_t j : {k - 1, k + 1}) {
      if (j >= n) continue;                            // k − 1 wraps for k = 0
      if (d.starts_session(std::max(j, k))) continue;  // another session's sample is no neighbour
      if (std::abs(current(j) - current(k)) > kTransitionShare * i_span ||
          std::abs(speed(j) - speed(k)) > kTransitionShare * n_span) {
        d.samples.set_mark(k, sample_mark::kLeftOut, true);
        ++d.excluded_transitional;
        break;
      }
    }
  }
}

/// A folder whose sessions both log d/q voltages and rebuild them from the duty cycle (VESC Tool 1.17–1.19 beside
/// later versions): the rebuilt sessions' u_d is the configuration's R_s·i_d − ω·L_q·i_q, so in one fit with the
/// others they would pull L_q (and, where the frame is sensorless, R_s through the open-loop start-ups no lock test
/// excludes) towards the configuration, and what that leaves would be named as an effect. The logged sessions carry
/// those constants: the rebuilt ones are left out, marked and counted, rather than the constants withheld from all.
void leave_out_rebuilt_sessions(LogData& d) {
  const std::vector<bool>& rebuilt = d.session_voltage_rebuilt;
  if (rebuilt.size() != d.sessions()) return;  // phase-sample logs carry no such flag
  const auto count = static_cast<std::size_t>(std::count(rebuilt.begin(), rebuilt.end(), true));
  if (count == 0 || count == rebuilt.size()) return;
  for (std::size_t j = 0; j < d.sessions(); ++j) {
    if (!rebuilt[j]) continue;
    for (std::size_t k = d.session_first[j]; k < d.session_end(j); ++k) {
      d.samples.set_mark(k, sample_mark::kLeftOut, true);
      ++d.excluded_rebuilt;
    }
  }
}

}  // namespace

void prepare_log(LogData& d, const core::MachineSi& machine, const LogOptions& options) {
  const std::size_t n = d.samples.size();
  check_enough_samples(d, options);
  if (d.session_logs.empty()) d.session_logs.push_back(d.path);  // rows from memory: one session
  assert(d.session_logs.size() == d.session_first.size() && d.session_first.front() == 0);
  assert(std::is_sorted(d.session_first.begin(), d.session_first.end()) && d.session_first.back() < n);
  d.t_start_s = d.t_s(0);
  d.t_end_s = d.t_s(n - 1);
  {
    std::vector<double> dts;
    dts.reserve(n - 1);
    for (std::size_t k = 1; k < n; ++k) {
      if (!d.starts_session(k)) dts.push_back(core::to_seconds(d.samples.t_ns(k) - d.samples.t_ns(k - 1)));
    }
    d.median_dt_s = median(std::move(dts));
  }

  // The measured current's amplitude, the same in every frame (amplitude-invariant).
  double u_dc_sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    d.max_current_A = std::max(d.max_current_A, d.logged_i_dq_A(k).norm());
    d.max_speed_rad_s = std::max(d.max_speed_rad_s, std::abs(d.samples.omega_el_rad_s(k)));
    u_dc_sum += d.samples.u_dc_V(k);
  }
  d.mean_u_dc_V = u_dc_sum / static_cast<double>(n);
  {
    std::vector<double> moving;
    for (std::size_t k = 0; k < n; ++k) {
      const double w = d.samples.omega_el_rad_s(k);
      if (std::abs(w) > 0.05 * d.max_speed_rad_s) moving.push_back(std::abs(w));
    }
    if (!moving.empty()) {
      std::sort(moving.begin(), moving.end());
      d.speed_spread_rel =
          (moving[moving.size() * 9 / 10] - moving[moving.size() / 10]) / std::max(d.max_speed_rad_s, 1e-12);
    }
  }

  const double time_constant_s = std::max(machine.l_d_H, machine.l_q_H) / machine.r_s_Ohm;
  d.mode = options.mode.value_or(d.median_dt_s >= kSteadyStateTimeConstants * time_constant_s ? ModelMode::kSteadyState
                                                                                              : ModelMode::kTransient);
  d.speed_half_window = d.mode == ModelMode::kTransient ? std::max(0, options.speed_half_window) : 0;

  leave_out_rebuilt_sessions(d);
  if (d.mode == ModelMode::kSteadyState) leave_out_idle_and_transitional(d);

  // Block b holds the samples whose sampled time lies in [b, b + 1)·span/blocks (the last one's end included):
  // the time since the first sample with the pauses left out, so that a log of two recordings joined still
  // trains and holds out on every part of both.
  const std::vector<double> sampled = sampled_time_s(d);
  d.blocks = std::max(2, options.blocks);
  d.block_first.assign(static_cast<std::size_t>(d.blocks) + 1, n);
  const double span = std::max(sampled.empty() ? 0.0 : sampled.back(), 1e-12);
  int next = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const int b = std::min(d.blocks - 1, static_cast<int>(sampled[k] / span * d.blocks));
    for (; next <= b; ++next) d.block_first[static_cast<std::size_t>(next)] = k;
  }
}

LogData prepare_log(const std::vector<io::DriveLogRow>& rows, const io::DriveLogLayout& layout,
                    const core::MachineSi& machine, const LogOptions& options, const std::string& path) {
  LogData d;
  d.path = path;
  d.layout = layout;
  d.samples = SampleStore(layout);
  for (const io::DriveLogRow& r : rows) d.samples.push_back(r);
  d.samples.finish();
  prepare_log(d, machine, options);
  return d;
}

std::vector<std::string> left_out_explanations(const LogData& log) {
  std::vector<std::string> out;
  const double n = static_cast<double>(log.size());
  // Said where the rule took more than `share` of the rows (whole sessions: whatever their share).
  auto explain = [&](std::size_t count, const std::string& what, double share = io::kExplainedShare) {
    if (count == 0 || static_cast<double>(count) <= share * n) return;
    char head[96];
    std::snprintf(head, sizeof head, "%zu of %zu rows (%.1f %%) ", count, log.size(),
                  100.0 * static_cast<double>(count) / n);
    out.push_back(head + what);
  };
  char text[512];
  std::snprintf(text, sizeof text,
                "were left out of the steady-state replay as in transition: their current or speed differs from a "
                "neighbour's by more than %.0f %% of the log's range, so they are not at a steady operating point. "
                "Keys: none — a log of samples at the control rate replays the transient model (--model transient), "
                "and a faster logger gives rows a neighbour at the same operating point",
                100.0 * kTransitionShare);
  explain(log.excluded_transitional, text);
  std::snprintf(text, sizeof text,
                "were left out as idle: current and speed both below %.0f %% of their largest, where the model "
                "predicts nothing a constant could be fitted to. Keys: none (nothing to fit there)",
                100.0 * kIdleShare);
  explain(log.excluded_idle, text);
  std::string names;
  for (std::size_t j = 0; j < log.session_voltage_rebuilt.size(); ++j) {
    if (log.session_voltage_rebuilt[j]) names += (names.empty() ? "" : ", ") + log.session_logs[j];
  }
  explain(log.excluded_rebuilt,
          "were left out: they are the sessions whose voltages are rebuilt from the duty cycle (" + names +
              "), whose u_d holds the configuration's R_s and L_q, while the folder's other sessions log the d/q "
              "voltages, which carry them (docs/diagnose.md, \"A folder of logs\"). Keys: none — diagnose those "
              "sessions on their own to use them",
          0.0);
  return out;
}

void require_samples_to_fit(const LogData& log, const std::vector<std::string>& why) {
  const std::size_t training = log.training_count(),
                    heldout = log.used_count() - training;  // a used sample is one or the other
  if (training >= 2 && heldout >= 2) return;
  std::string message = "nothing to diagnose: of its " + std::to_string(log.size()) + " samples, " +
                        std::to_string(training) + " in the training blocks and " + std::to_string(heldout) +
                        " held out take part, and at least 2 of each are needed";
  for (const std::string& w : why) message += "; " + w;
  throw io::DriveLogError(log.path, 0, 0, "", message);
}

core::Vec2 applied_mean_V(const core::Vec2& command_V, double omega_el_rad_s, double control_period_s,
                          double delay_periods) noexcept {
  const double wt = omega_el_rad_s * control_period_s;
  const double half = 0.5 * wt;
  const double sinc = core::sinc(half);
  // Turned by −d·ω·T_c: the Park transform by the angle the rotor advances before the hold's centre.
  return sinc * core::park(command_V, core::Rotation::of(delay_periods * wt));
}

LogOptions log_options(const io::MachineConfig& config) {
  LogOptions o;
  o.voltage_is_command = config.estimator.averaged.voltage_is_command;
  o.control_period_s = config.estimator.averaged.control_period_s;
  o.command_delay_s = config.estimator.extensions.delay_s;
  o.staircase_below_rad_s = config.estimator.regimes.hall_interpolation_speed_rad_s;
  return o;
}

}  // namespace rpem::analysis
