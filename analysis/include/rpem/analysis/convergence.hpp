#pragma once
// Convergence metrics of an estimate trajectory after a parameter step (reproduce.json):
//   convergence_time_s     from the step until the estimate enters and stays within ±band of the true value
//   steady_state_error_pct mean relative error over the final window, signed, in % of the true value
//   overshoot_pct          largest excursion past the true value, against the direction of approach, in %
//   wrong_way_pct          largest move from the estimate at the step away from the true value (the wrong
//                          way), in % of the true value

#include <optional>
#include <string>
#include <vector>

namespace rpem::analysis {

struct TrajectoryPoint {
  double t_s = 0.0;
  double estimate = 0.0;
  double truth = 0.0;
};

struct ConvergenceMetrics {
  std::optional<double> convergence_time_s;  ///< empty: never settled within the band
  double steady_state_error_pct = 0.0;
  double overshoot_pct = 0.0;
  double wrong_way_pct = 0.0;
};

struct ConvergenceOptions {
  double step_time_s = 0.0;     ///< the step (or start of adaptation)
  double band = 0.01;           ///< ±1 %
  double final_window_s = 1.0;  ///< steady-state error: mean over the last window
};

/// "1.23" or "—" when the estimate never settled.
[[nodiscard]] std::string format_seconds(const std::optional<double>& t_s);

[[nodiscard]] ConvergenceMetrics convergence_metrics(const std::vector<TrajectoryPoint>& trajectory,
                                                     const ConvergenceOptions& options);

}  // namespace rpem::analysis
