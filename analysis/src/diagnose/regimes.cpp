#include "rpem/analysis/diagnose/regimes.hpp"

#include <cassert>
#include <cmath>
#include <limits>
#include <optional>

#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/core/settings.hpp"

namespace rpem::analysis {
namespace {

using core::kNaN;

/// An averaged log's row as the window it was read from (io::to_drive_log_row inverted).
core::AveragedSample window_of(const LogData& log, std::size_t k) {
  const core::DriveSample r = log.sample(k);
  core::AveragedSample s;
  s.t_start_ns = log.window_start_ns[k];
  s.t_ns = r.t_ns;
  s.i_dq_A = r.i_A.head<2>();
  s.u_dq_V = log.window_reported_u_V[k];  // as reported: the estimator turns a command itself, as in rpem estimate
  s.omega_el_rad_s = r.omega_el_rad_s;    // the counted speed already taken where the angle is a staircase (at reading)
  s.omega_el_error_rad_s = log.window_speed_error_rad_s[k];
  s.omega_el_error_noise_rad_s = log.window_speed_error_noise_rad_s[k];
  s.omega_el_at_reads_max_rad_s = log.window_speed_at_reads_max_rad_s[k];
  s.u_dc_V = log.layout.u_dc ? r.u_dc_V : kNaN;
  s.t_winding_C = log.samples.t_winding_C(k).value_or(kNaN);
  s.t_magnet_C = log.samples.t_magnet_C(k).value_or(kNaN);
  s.gap_before = r.gap_before;
  return s;
}

}  // namespace

LogRegimes classify_regimes(const LogData& log, const io::MachineConfig& config, Monitor* monitor) {
  LogRegimes out;
  const std::size_t n = log.size();
  out.regime.resize(n);
  out.counts.averaged = log.averaged;
  auto record = [&](std::size_t k, const core::Estimate& e) {
    out.regime[k] = e.regime.regime;
    // The window before held the bridge's release (docs/derivations.md §13, "Mixed windows").
    if ((e.regime.bits & core::regime_bit::kPreviousMixed) && k > 0) out.regime[k - 1] = core::as_mixed(out.regime[k - 1]);
    out.counts.add(e);
    if ((k + 1) % kMonitorSamples == 0) report_work(monitor, kMonitorSamples);
  };
  if (log.averaged) {
    assert(log.window_start_ns.size() == n && log.window_speed_error_rad_s.size() == n &&
           log.window_speed_error_noise_rad_s.size() == n && log.window_speed_at_reads_max_rad_s.size() == n &&
           log.window_reported_u_V.size() == n && log.session_voltage_rebuilt.size() == log.sessions());
    // Each session from the configuration, as its log alone in rpem estimate: rebuilt voltages are applied means,
    // not turned again (io::estimator_settings); reported ones are turned by the estimator where they are commands.
    std::optional<core::AveragedDriveEstimator> estimator;
    for (std::size_t j = 0; j < log.sessions(); ++j) {
      estimator.emplace(config.machine,
                        log.session_voltage_rebuilt[j] ? core::for_applied_voltages(config.estimator) : config.estimator);
      out.counts.start_session();
      for (std::size_t k = log.session_first[j]; k < log.session_end(j); ++k) record(k, estimator->step(window_of(log, k)));
    }
    out.noise_pu = estimator->classifier().current_noise();
  } else {
    core::DriveEstimator estimator(config.machine, config.estimator);
    for (std::size_t k = 0; k < n; ++k) {
      if (log.starts_session(k)) {
        estimator.reset();
        out.counts.start_session();
      }
      record(k, estimator.step(log.sample(k)));
    }
    out.noise_pu = estimator.classifier().current_noise();
  }
  report_work(monitor, n % kMonitorSamples);
  out.explanations = io::exclusion_explanations(out.counts);
  return out;
}

void exclude_regimes(LogData& log, LogRegimes& regimes) {
  assert(regimes.regime.size() == log.size());
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (!core::info(regimes.regime[k]).excluded || !log.used(k)) continue;
    log.samples.set_mark(k, sample_mark::kLeftOut, true);
    ++regimes.excluded_used;
  }
}

}  // namespace rpem::analysis
