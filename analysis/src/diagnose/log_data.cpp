#include "rpem/analysis/diagnose/log_data.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/conditioner.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/io/machine_config.hpp"

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
  d.t_start_s = 1e-9 * static_cast<double>(d.rows.front().sample.t_ns);
  d.t_end_s = 1e-9 * static_cast<double>(d.rows.back().sample.t_ns);

  std::vector<double> dts;
  dts.reserve(n - 1);
  for (std::size_t k = 1; k < n; ++k) dts.push_back(1e-9 * static_cast<double>(d.rows[k].sample.t_ns - d.rows[k - 1].sample.t_ns));
  d.median_dt_s = median(dts);

  // The measured current's amplitude, the same in every frame (amplitude-invariant).
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  const core::SampleConditioner raw(base, core::to_pu(base, machine), {});
  std::vector<double> current(n), speed(n);
  double u_dc_sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const core::DriveSample& s = d.rows[k].sample;
    current[k] = raw.logged_current_dq_A(s).norm();
    speed[k] = s.omega_el_rad_s;
    d.max_current_A = std::max(d.max_current_A, current[k]);
    d.max_speed_rad_s = std::max(d.max_speed_rad_s, std::abs(speed[k]));
    u_dc_sum += s.u_dc_V;
  }
  d.mean_u_dc_V = u_dc_sum / static_cast<double>(n);

  const double time_constant_s = std::max(machine.l_d_H, machine.l_q_H) / machine.r_s_Ohm;
  d.mode = options.mode.value_or(d.median_dt_s >= kSteadyStateTimeConstants * time_constant_s ? ModelMode::kSteadyState
                                                                                               : ModelMode::kTransient);

  d.replay_speed_rad_s = speed;
  if (d.mode == ModelMode::kTransient && options.speed_half_window > 0) {
    const std::size_t w = static_cast<std::size_t>(options.speed_half_window);
    for (std::size_t k = w; k + w < n; ++k) {
      const core::DriveSample &a = d.rows[k - w].sample, &b = d.rows[k + w].sample;
      const double dt = 1e-9 * static_cast<double>(b.t_ns - a.t_ns);
      // Only across a gap-free stretch; else the logged speed stays.
      bool gap = false;
      for (std::size_t j = k - w + 1; j <= k + w && !gap; ++j) gap = d.rows[j].sample.gap_before;
      if (!gap && dt > 0.0) d.replay_speed_rad_s[k] = core::wrap_angle(b.theta_el_rad - a.theta_el_rad) / dt;
    }
  }

  d.used.assign(n, true);
  if (d.mode == ModelMode::kSteadyState) {
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

  d.blocks = std::max(2, options.blocks);
  d.block.resize(n);
  const double span = std::max(d.t_end_s - d.t_start_s, 1e-12);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = 1e-9 * static_cast<double>(d.rows[k].sample.t_ns) - d.t_start_s;
    d.block[k] = std::min(d.blocks - 1, static_cast<int>(t / span * d.blocks));
  }
  return d;
}

LogData load_log(const std::string& path, const core::MachineSi& machine, const LogOptions& options) {
  io::DriveLogReader reader(path, io::machine_limits(machine));
  std::vector<io::DriveLogRow> rows;
  io::DriveLogRow row;
  while (reader.next(row)) rows.push_back(row);
  return prepare_log(std::move(rows), reader.layout(), machine, options, path);
}

}  // namespace rpem::analysis
