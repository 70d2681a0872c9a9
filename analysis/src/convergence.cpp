#include "rpem/analysis/convergence.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rpem::analysis {

std::string format_seconds(const std::optional<double>& t_s) {
  if (!t_s) return "—";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", *t_s);
  return buf;
}

ConvergenceMetrics convergence_metrics(const std::vector<TrajectoryPoint>& tr, const ConvergenceOptions& o) {
  ConvergenceMetrics m;
  if (tr.empty()) return m;
  const double t_end = tr.back().t_s;

  // Direction of approach: the sign of the error at the step.
  double initial_error = 0.0;
  double start_estimate = 0.0;
  for (const TrajectoryPoint& p : tr) {
    if (p.t_s >= o.step_time_s) {
      initial_error = p.estimate - p.truth;
      start_estimate = p.estimate;
      break;
    }
  }
  const double approach = initial_error > 0.0 ? -1.0 : 1.0;  // the estimate moves in this direction

  std::optional<double> last_outside;
  double sum = 0.0;
  int count = 0;
  for (const TrajectoryPoint& p : tr) {
    if (p.t_s < o.step_time_s) continue;
    const double rel = (p.estimate - p.truth) / p.truth;
    if (std::abs(rel) > o.band) last_outside = p.t_s;
    m.overshoot_pct = std::max(m.overshoot_pct, 100.0 * approach * rel);
    m.wrong_way_pct = std::max(m.wrong_way_pct, -100.0 * approach * (p.estimate - start_estimate) / p.truth);
    if (p.t_s >= t_end - o.final_window_s) {
      sum += rel;
      ++count;
    }
  }
  m.steady_state_error_pct = count > 0 ? 100.0 * sum / count : 0.0;
  // Settled if the estimate is inside the band at the end; the time is the first sample after the last
  // excursion.
  const double final_rel = std::abs((tr.back().estimate - tr.back().truth) / tr.back().truth);
  if (final_rel <= o.band) {
    m.convergence_time_s = last_outside ? *last_outside - o.step_time_s : 0.0;
  }
  return m;
}

}  // namespace rpem::analysis
