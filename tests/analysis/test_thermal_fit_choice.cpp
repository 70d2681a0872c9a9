// The test that keeps the random-walk disturbance unless the training likelihood rejects it (eq. 14.21a).
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/analysis/thermal/thermal_fit.hpp"

namespace rpem::analysis {
namespace {

// ½·χ²₁ quantiles from the normal's: χ²₁(1 − α) = z²(1 − α/2). Reference values of z from the normal table
// (Abramowitz & Stegun 26.2), one-sided tails: 1.959964 at 2.5 %, 2.638257 at 0.05/12, 3.290527 at 0.05 %.
TEST(ThermalFitChoice, LikelihoodRatioThresholdIsHalfTheChiSquareQuantile) {
  EXPECT_NEAR(likelihood_ratio_threshold(1), 0.5 * 1.959964 * 1.959964, 1e-5);
  EXPECT_NEAR(likelihood_ratio_threshold(6), 0.5 * 2.638257 * 2.638257, 1e-5);  // the fit's grid: 3.48
  EXPECT_NEAR(likelihood_ratio_threshold(50), 0.5 * 3.290527 * 3.290527, 1e-5);
  EXPECT_NEAR(likelihood_ratio_threshold(0), likelihood_ratio_threshold(1), 0.0);  // no grid: one trial
}

TEST(ThermalFitChoice, MoreTrialsAskMoreEvidence) {
  double before = 0.0;
  for (std::size_t m = 1; m <= 64; m *= 2) {
    const double t = likelihood_ratio_threshold(m);
    EXPECT_GT(t, before) << m;
    before = t;
  }
}

}  // namespace
}  // namespace rpem::analysis
