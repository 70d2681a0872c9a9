// The drop along the current at the windows R_s adapted on (eq. 12.1, rpem/analysis/rs_along_current.hpp): readings
// made as R(t)·|i| + V + noise, with R drifting linearly, give R at the last reading and V back within their stated
// standard errors; too few readings, or one current, give no fit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "rpem/analysis/rs_along_current.hpp"

namespace rpem::analysis {
namespace {

constexpr double kROhm = 0.0185, kDriftOhmPerS = 2e-6, kVoltageV = 0.025, kNoiseV = 0.01;

/// `n` readings over 200 s, alternating between 5.7 A and 25–55 A, of R(t)·|i| + V with white noise of kNoiseV.
std::vector<RsReading> drifting_readings(int n, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, kNoiseV);
  std::vector<RsReading> out;
  for (int k = 0; k < n; ++k) {
    const double t_s = 200.0 * k / (n - 1), current_A = k % 2 == 0 ? 5.7 : 25.0 + 30.0 * (k % 3) / 2.0;
    out.push_back({t_s, current_A, (kROhm + kDriftOhmPerS * t_s) * current_A + kVoltageV + noise(rng)});
  }
  return out;
}

TEST(RsAlongCurrent, GivesTheResistanceAtTheLastReadingAndTheVoltageWithinTheirErrors) {
  // Over 400 logs of 40 readings: each estimate within 4 of its own standard errors, and the standardised errors'
  // RMS within 15 % of 1 (an se that says what the scatter is; 400 draws: the RMS's own spread is ±3.5 %).
  double r_z2 = 0.0, v_z2 = 0.0;
  constexpr int kLogs = 400;
  for (int log = 0; log < kLogs; ++log) {
    std::mt19937 rng(static_cast<unsigned>(log + 1));
    const std::vector<RsReading> readings = drifting_readings(40, rng);
    const auto fit = fit_rs_along_current(readings);
    ASSERT_TRUE(fit.has_value());
    const double r_true = kROhm + kDriftOhmPerS * readings.back().t_s;
    const double r_z = (fit->r_at_last_Ohm - r_true) / fit->r_at_last_se_Ohm, v_z = (fit->v_V - kVoltageV) / fit->v_se_V;
    EXPECT_LT(std::abs(r_z), 4.0) << log;
    EXPECT_LT(std::abs(v_z), 4.0) << log;
    r_z2 += r_z * r_z / kLogs, v_z2 += v_z * v_z / kLogs;
    EXPECT_EQ(fit->readings, 40u);
    EXPECT_DOUBLE_EQ(fit->current_min_A, 5.7);
  }
  EXPECT_NEAR(std::sqrt(r_z2), 1.0, 0.15);
  EXPECT_NEAR(std::sqrt(v_z2), 1.0, 0.15);
}

TEST(RsAlongCurrent, FewReadingsOrOneCurrentGiveNoFit) {
  std::mt19937 rng(3);
  std::vector<RsReading> readings = drifting_readings(5, rng);
  EXPECT_FALSE(fit_rs_along_current(readings).has_value());  // fewer than six
  readings = drifting_readings(12, rng);
  for (RsReading& r : readings) r.current_A = 10.0;  // one current: R and V are one
  EXPECT_FALSE(fit_rs_along_current(readings).has_value());
}

}  // namespace
}  // namespace rpem::analysis
