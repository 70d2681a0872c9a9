#include <gtest/gtest.h>

#include <cmath>

#include "rpem/analysis/convergence.hpp"

namespace rpem::analysis {
namespace {

TEST(Convergence, FirstOrderApproachSettlesAtTheAnalyticTime) {
  // e(t) = 8.7 %·exp(−(t − 1)/τ): inside ±1 % from t − 1 = τ·ln(8.7).
  const double tau = 0.4, truth = 1.0;
  std::vector<TrajectoryPoint> tr;
  for (double t = 0.0; t <= 6.0; t += 1e-4) {
    const double e = t < 1.0 ? 0.087 : 0.087 * std::exp(-(t - 1.0) / tau);
    tr.push_back({t, truth * (1.0 + e), truth});
  }
  const ConvergenceMetrics m = convergence_metrics(tr, {1.0, 0.01, 1.0});
  ASSERT_TRUE(m.convergence_time_s);
  EXPECT_NEAR(*m.convergence_time_s, tau * std::log(8.7), 2e-4);
  EXPECT_NEAR(m.steady_state_error_pct, 0.0, 0.01);
  EXPECT_EQ(m.overshoot_pct, 0.0);
}

TEST(Convergence, WrongWayIsTheMoveAwayFromTheTruthBeyondTheStartingEstimate) {
  // Truth 1.0, the estimate starts at 1.1 (approach: downwards), first rises to 1.15 (t = 1.5), then decays to the
  // truth from 1.1 at t = 2: 5 % of the true value the wrong way, no overshoot.
  std::vector<TrajectoryPoint> tr;
  for (int k = 0; k <= 6000; ++k) {
    const double t = 1e-3 * k;
    double est = 1.1;
    if (t >= 1.0 && t < 2.0) est = 1.1 + 0.05 * std::sin(M_PI * (t - 1.0));
    if (t >= 2.0) est = 1.0 + 0.1 * std::exp(-3.0 * (t - 2.0));
    tr.push_back({t, est, 1.0});
  }
  const ConvergenceMetrics m = convergence_metrics(tr, {1.0, 0.01, 1.0});
  EXPECT_NEAR(m.wrong_way_pct, 5.0, 1e-9);
  EXPECT_EQ(m.overshoot_pct, 0.0);
}

TEST(Convergence, OvershootAndLateExcursion) {
  std::vector<TrajectoryPoint> tr;
  for (double t = 0.0; t <= 5.0; t += 0.01) {
    double est = 1.1;
    if (t >= 1.0) est = 1.0 - 0.06 * std::exp(-(t - 1.0)) * std::cos(3.0 * (t - 1.0) - 1.4);
    if (t > 3.0 && t < 3.05) est = 1.02;  // a late excursion resets the settling time
    tr.push_back({t, est, 1.0});
  }
  const ConvergenceMetrics m = convergence_metrics(tr, {1.0, 0.01, 1.0});
  ASSERT_TRUE(m.convergence_time_s);
  EXPECT_NEAR(*m.convergence_time_s, 2.05, 0.011);
  EXPECT_GT(m.overshoot_pct, 2.0);  // approaching from above, it went below the truth
}

TEST(Convergence, NeverSettledIsEmpty) {
  std::vector<TrajectoryPoint> tr;
  for (double t = 0.0; t <= 2.0; t += 0.01) tr.push_back({t, 1.5, 1.0});
  const ConvergenceMetrics m = convergence_metrics(tr, {0.0, 0.01, 0.5});
  EXPECT_FALSE(m.convergence_time_s);
  EXPECT_NEAR(m.steady_state_error_pct, 50.0, 1e-9);
  EXPECT_EQ(format_seconds(m.convergence_time_s), "—");
}

}  // namespace
}  // namespace rpem::analysis
