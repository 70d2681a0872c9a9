// The derating law (examples/supervisor/include/rpem/supervisor/derating.hpp, docs/supervisor.md):
// hand-worked points of the written formula, then seeded random parts and temperatures against the
// formula recomputed here, and its invariants (bounded, non-increasing in T⁺, continuous on (−∞, L]).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "rpem/supervisor/derating.hpp"
#include "support/seed.hpp"

namespace rpem::supervisor {
namespace {

// W = 100 °C, L = 140 °C, F = 30 A, I_r = 120 A: the slope is (120 − 30)/40 = 2.25 A/K.
const PartLimits kMagnet{100.0, 140.0, 30.0, 4.0, 0.05};
constexpr double kRated = 120.0;

TEST(Derating, HandWorkedPointsOfTheLaw) {
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, 20.0), 120.0);         // cold
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, 100.0), 120.0);        // at W: still full
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, 110.0), 97.5);         // 120 − 2.25·10
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, 120.0), 75.0);         // half way: (120 + 30)/2
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, 140.0), 30.0);         // at L: the floor
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, 140.01), 0.0);         // above L: nothing
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, std::nullopt), 30.0);  // unknown: taken to be at L
  EXPECT_DOUBLE_EQ(part_current_A(kMagnet, kRated, std::numeric_limits<double>::quiet_NaN()), 30.0);
  // A floor of zero: linear to nothing at L.
  PartLimits to_zero = kMagnet;
  to_zero.floor_A = 0.0;
  EXPECT_DOUBLE_EQ(part_current_A(to_zero, kRated, 130.0), 30.0);  // 120·(1 − 30/40)
  EXPECT_DOUBLE_EQ(part_current_A(to_zero, kRated, std::nullopt), 0.0);
}

TEST(Derating, UpperBoundIsTheEstimatePlusTwoSigmaPlusTheHeatingSinceItWasRenewed) {
  // 80 + 2·4 + 0.05 K/s · 10 s = 88.5
  EXPECT_DOUBLE_EQ(upper_bound_C(kMagnet, TemperatureEstimate{80.0, 4.0, 10.0}), 88.5);
  EXPECT_DOUBLE_EQ(upper_bound_C(kMagnet, TemperatureEstimate{80.0, 0.0, 0.0}), 80.0);
}

TEST(Derating, SeededPartsFollowTheFormulaAndItsInvariants) {
  std::mt19937_64 rng(test::test_seed(2401));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 100000; ++n) {
    const double rated = 1.0 + 500.0 * u(rng);
    PartLimits p;
    p.warning_C = -20.0 + 200.0 * u(rng);
    p.limit_C = p.warning_C + 0.1 + 100.0 * u(rng);
    p.floor_A = rated * u(rng);
    const double t = p.warning_C - 50.0 + (p.limit_C - p.warning_C + 100.0) * u(rng);
    const double expected = t <= p.warning_C ? rated
                            : t <= p.limit_C ? rated - (rated - p.floor_A) * (t - p.warning_C) / (p.limit_C - p.warning_C)
                                             : 0.0;
    const double i = part_current_A(p, rated, t);
    ASSERT_NEAR(i, expected, 1e-12 * rated) << "n " << n << " T+ " << t;
    ASSERT_GE(i, 0.0);
    ASSERT_LE(i, rated);
    // Non-increasing: 0.5 K hotter never gives more current.
    ASSERT_LE(part_current_A(p, rated, t + 0.5), i + 1e-12 * rated) << "n " << n << " T+ " << t;
    // Continuous up to and at L: the floor is approached from the ramp.
    if (t > p.warning_C && t < p.limit_C) {
      ASSERT_NEAR(part_current_A(p, rated, p.limit_C - 1e-9), p.floor_A, 1e-6 * rated);
    }
  }
}

}  // namespace
}  // namespace rpem::supervisor
