// The command delay, recovered by cross-correlating the logged command with the applied voltage: with
// y[k] = (1 − f)·x[k − n] + f·x[k − n − 1] (α components, first differences), the cross-correlation peaks at
// lag n, and the two-tap normal equations built from the cross- and autocorrelation give f.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "case_fixtures.hpp"
#include "indep_drive/generator.hpp"

namespace indep {
namespace {

double correlation(const std::vector<double>& x, const std::vector<double>& y, int lag) {
  double s = 0.0;
  for (std::size_t k = 8; k + 8 < x.size(); ++k) s += x[k - static_cast<std::size_t>(lag) + 4] * y[k + 4];
  return s;
}

/// The delay in control periods estimated from the log and the plant.
double estimated_delay(const Result& r) {
  std::vector<double> x, y;
  for (std::size_t k = 1; k < r.log.size(); ++k) {
    x.push_back(clarke(r.log[k].u_abc_V).x - clarke(r.log[k - 1].u_abc_V).x);
    y.push_back(r.plant[k].u_applied_ab_V.x - r.plant[k - 1].u_applied_ab_V.x);
  }
  int best = 0;
  for (int lag = 0; lag <= 4; ++lag) {
    if (std::abs(correlation(x, y, lag)) > std::abs(correlation(x, y, best))) best = lag;
  }
  // Two taps a at lag n and b at lag n+1 (n the peak or the one before it, whichever fits better).
  double best_error = INFINITY, delay = NAN;
  for (int n : {best - 1, best}) {
    if (n < 0) continue;
    const double r0 = correlation(x, x, 0), r1 = correlation(x, x, 1);
    const double c0 = correlation(x, y, n), c1 = correlation(x, y, n + 1);
    const double det = r0 * r0 - r1 * r1;
    const double a = (r0 * c0 - r1 * c1) / det, b = (r0 * c1 - r1 * c0) / det;
    const double error = std::abs(a + b - 1.0) + std::min(0.0, std::min(a, b)) * -1.0;
    if (error < best_error) {
      best_error = error;
      delay = n + b / (a + b);
    }
  }
  return delay;
}

Case delay_case(double periods) {
  Case c = testing::ideal_case();
  c.seed = 3;
  c.duration_s = 1.0;
  // Speed ramps and torque steps: a command with broad spectrum.
  c.profile.points = {{0.0, 0, 10, 0},   {0.2, 300, 10, 0}, {0.2, 300, -15, 0}, {0.5, 100, -15, 0},
                      {0.5, 100, 25, 0}, {0.8, 400, 25, 0}, {0.8, 400, 5, 0},   {1.0, 200, 5, 0}};
  if (periods > 0.0) {
    c.effects.delay.on = true;
    c.effects.delay.periods = periods;
  }
  return c;
}

TEST(IndepDelay, CrossCorrelationFindsWholeAndFractionalDelays) {
  for (double periods : {0.0, 1.0, 2.0, 3.0, 2.4, 0.7}) {
    const Result r = generate(delay_case(periods));
    EXPECT_NEAR(estimated_delay(r), periods, 0.01) << periods;
    if (periods > 0.0) {
      EXPECT_NEAR(r.truth.effect("delay")->value("delay_s"), periods * 125e-6, 1e-15);
    }
  }
}

}  // namespace
}  // namespace indep
