#include "rpem/analysis/diagnose/log_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rpem/core/clock.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/log_source.hpp"
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

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The measured current's amplitude and the speed per row, their largest values, the mean DC voltage and
/// the spread of the moving speeds.
void measure_amplitudes(LogData& d, const core::MachineSi& machine, std::vector<double>& current,
                        std::vector<double>& speed) {
  const std::size_t n = d.rows.size();
  // The measured current's amplitude, the same in every frame (amplitude-invariant).
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  const core::SampleConditioner raw(base, core::to_pu(base, machine), {});
  d.logged_i_dq_A.resize(n);
  double u_dc_sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const core::DriveSample& s = d.rows[k].sample;
    d.logged_i_dq_A[k] = raw.logged_current_dq_A(s);
    current[k] = d.logged_i_dq_A[k].norm();
    speed[k] = s.omega_el_rad_s;
    d.max_current_A = std::max(d.max_current_A, current[k]);
    d.max_speed_rad_s = std::max(d.max_speed_rad_s, std::abs(speed[k]));
    u_dc_sum += s.u_dc_V;
  }
  d.mean_u_dc_V = u_dc_sum / static_cast<double>(n);
  std::vector<double> moving;
  for (double w : speed) {
    if (std::abs(w) > 0.05 * d.max_speed_rad_s) moving.push_back(std::abs(w));
  }
  if (!moving.empty()) {
    std::sort(moving.begin(), moving.end());
    d.speed_spread_rel = (moving[moving.size() * 9 / 10] - moving[moving.size() / 10]) / std::max(d.max_speed_rad_s, 1e-12);
  }
}

/// The samples the replay runs on: the logged ones; in the transient mode with the speed taken from the
/// angle's change over ±half_window rows where that stretch has no gap.
void replay_samples(LogData& d, int half_window) {
  const std::size_t n = d.rows.size();
  d.replay_samples.resize(n);
  for (std::size_t k = 0; k < n; ++k) d.replay_samples[k] = d.rows[k].sample;
  if (d.mode != ModelMode::kTransient || half_window <= 0) return;
  const std::size_t w = static_cast<std::size_t>(half_window);
  for (std::size_t k = w; k + w < n; ++k) {
    const core::DriveSample &a = d.rows[k - w].sample, &b = d.rows[k + w].sample;
    const double dt = core::to_seconds(b.t_ns - a.t_ns);
    // Only across a gap-free stretch; else the logged speed stays.
    bool gap = false;
    for (std::size_t j = k - w + 1; j <= k + w && !gap; ++j) gap = d.rows[j].sample.gap_before;
    if (!gap && dt > 0.0) d.replay_samples[k].omega_el_rad_s = core::wrap_angle(b.theta_el_rad - a.theta_el_rad) / dt;
  }
}

/// The steady-state replay leaves out idle rows and rows whose neighbour's current or speed differs by
/// more than kTransitionShare of the log's range.
void exclude_idle_and_transitional(LogData& d, const std::vector<double>& current, const std::vector<double>& speed) {
  const std::size_t n = d.rows.size();
  const double i_span = std::max(d.max_current_A, 1e-9), n_span = std::max(d.max_speed_rad_s, 1e-9);
  for (std::size_t k = 0; k < n; ++k) {
    if (current[k] < kIdleShare * i_span && std::abs(speed[k]) < kIdleShare * n_span) {
      d.used[k] = false;
      ++d.excluded_idle;
      continue;
    }
    for (std::size_t j : {k - 1, k + 1}) {
      if (j >= n) continue;  // k − 1 wraps for k = 0
      if (std::abs(current[j] - current[k]) > kTransitionShare * i_span ||
          std::abs(speed[j] - speed[k]) > kTransitionShare * n_span) {
        d.used[k] = false;
        ++d.excluded_transitional;
        break;
      }
    }
  }
}

}  // namespace

const char* to_string(ModelMode m) noexcept { return m == ModelMode::kTransient ? "transient" : "steady_state"; }

LogData prepare_log(std::vector<io::DriveLogRow> rows, const io::DriveLogLayout& layout,
                    const core::MachineSi& machine, const LogOptions& options, const std::string& path) {
  LogData d;
  d.path = path;
  d.rows = std::move(rows);
  d.layout = layout;
  const std::size_t n = d.rows.size();
  if (n < 2 * static_cast<std::size_t>(std::max(2, options.blocks))) {
    throw io::DriveLogError(path, n + 1, 0, "", "a log to diagnose needs at least " +
                                                    std::to_string(2 * std::max(2, options.blocks)) + " rows");
  }
  d.t_start_s = core::to_seconds(d.rows.front().sample.t_ns);
  d.t_end_s = core::to_seconds(d.rows.back().sample.t_ns);

  std::vector<double> dts;
  dts.reserve(n - 1);
  for (std::size_t k = 1; k < n; ++k) dts.push_back(core::to_seconds(d.rows[k].sample.t_ns - d.rows[k - 1].sample.t_ns));
  d.median_dt_s = median(dts);

  std::vector<double> current(n), speed(n);
  measure_amplitudes(d, machine, current, speed);

  const double time_constant_s = std::max(machine.l_d_H, machine.l_q_H) / machine.r_s_Ohm;
  d.mode = options.mode.value_or(d.median_dt_s >= kSteadyStateTimeConstants * time_constant_s ? ModelMode::kSteadyState
                                                                                               : ModelMode::kTransient);

  replay_samples(d, options.speed_half_window);
  d.used.assign(n, true);
  if (d.mode == ModelMode::kSteadyState) exclude_idle_and_transitional(d, current, speed);

  d.blocks = std::max(2, options.blocks);
  d.block.resize(n);
  const double span = std::max(d.t_end_s - d.t_start_s, 1e-12);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = core::to_seconds(d.rows[k].sample.t_ns) - d.t_start_s;
    d.block[k] = std::min(d.blocks - 1, static_cast<int>(t / span * d.blocks));
  }
  return d;
}

std::vector<std::string> left_out_explanations(const LogData& log) {
  std::vector<std::string> out;
  const double n = static_cast<double>(log.rows.size());
  auto explain = [&](std::size_t count, const std::string& what) {
    if (static_cast<double>(count) <= io::kExplainedShare * n) return;
    char head[96];
    std::snprintf(head, sizeof head, "%zu of %zu rows (%.1f %%) ", count, log.rows.size(), 100.0 * static_cast<double>(count) / n);
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
  return out;
}

core::Vec2 applied_mean_V(const core::Vec2& command_V, double omega_el_rad_s, double control_period_s,
                          double delay_periods) noexcept {
  const double wt = omega_el_rad_s * control_period_s;
  const double half = 0.5 * wt;
  const double sinc = std::abs(half) < 1e-6 ? 1.0 - half * half / 6.0 : std::sin(half) / half;
  // Turned by −d·ω·T_c: the Park transform by the angle the rotor advances before the hold's centre.
  return sinc * core::park(command_V, core::Rotation::of(delay_periods * wt));
}

namespace {

/// Turns a drive's reported commands into the applied means (LogOptions::voltage_is_command); returns what it
/// did, for the log's description.
std::string apply_reported_command(std::vector<core::AveragedSample>& samples, const LogOptions& options) {
  // Held one period from the delay on: its centre d·T_c = delay + T_c/2 after the sample. Every sample, the
  // bridge-off ones too: at VESC Tool's 0.01 A a modulating bridge at zero current reads i = 0 as well, and the
  // undriven branch's measured back EMF is then turned too (docs/drive-log.md, "The voltage is the command").
  const double d = (options.command_delay_s + 0.5 * options.control_period_s) / options.control_period_s;
  for (core::AveragedSample& s : samples) s.u_dq_V = applied_mean_V(s.u_dq_V, s.omega_el_rad_s, options.control_period_s, d);
  char text[200];
  std::snprintf(text, sizeof text,
                "; voltages reported as the drive's command, turned into the applied mean (by −%.3g·ω·T_c, times "
                "sinc(ω·T_c/2), T_c = %.3g µs)",
                d, 1e6 * options.control_period_s);
  return text;
}

}  // namespace

LogData load_log(const std::string& path, const core::MachineSi& machine, const LogOptions& options) {
  const io::LogSource source = io::log_source(path, options.log_map);
  const io::DriveLogLimits limits = io::machine_limits(machine);
  if (source.averaged()) {
    // Window means carry no transient to replay: the steady-state model, whatever the spacing.
    if (options.mode == ModelMode::kTransient) {
      throw io::DriveLogError(path, 1, 0, "column t_start",
                              "an averaged log replays only the steady-state model (give --model auto or steady_state)");
    }
    io::AveragedLogRead read;
    std::vector<core::AveragedSample> samples = io::read_averaged_log(path, source.map, limits, &read);
    const bool turn = options.voltage_is_command && options.control_period_s > 0.0;
    const std::string voltage = turn ? apply_reported_command(samples, options) : "";
    std::vector<io::DriveLogRow> rows;
    std::vector<std::int64_t> starts;
    rows.reserve(samples.size());
    starts.reserve(samples.size());
    for (const core::AveragedSample& s : samples) {
      rows.push_back(io::to_drive_log_row(s));
      starts.push_back(s.t_start_ns);
    }
    LogOptions steady = options;
    steady.mode = ModelMode::kSteadyState;
    LogData d = prepare_log(std::move(rows), io::rotor_frame_layout(read.layout), machine, steady, path);
    d.averaged = true;
    d.window_start_ns = std::move(starts);
    d.format = io::describe(source, read) + voltage;
    d.voltage_applied = turn;
    return d;
  }
  io::DriveLogReader reader(path, source.map, limits);
  std::vector<io::DriveLogRow> rows;
  io::DriveLogRow row;
  while (reader.next(row)) rows.push_back(row);
  LogData d = prepare_log(std::move(rows), reader.layout(), machine, options, path);
  d.format = path + " as " + source.format + ": " + std::to_string(d.rows.size()) + " rows" +
             io::describe(reader.reader().repairs());
  return d;
}

}  // namespace rpem::analysis
