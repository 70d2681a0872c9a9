// The Ziggurat sampler against the normal distribution: moments and tail probabilities over 10⁶ draws
// (tolerances: several standard errors of each estimate).
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/sim/gaussian.hpp"
#include "support/seed.hpp"

namespace rpem::sim {
namespace {

TEST(GaussianNoise, MomentsAndTailsMatchTheStandardNormal) {
  GaussianNoise g(test::test_seed(17));
  constexpr int kN = 1'000'000;
  double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  int beyond1 = 0, beyond3 = 0, beyond_r = 0;
  for (int k = 0; k < kN; ++k) {
    const double x = g();
    m1 += x;
    m2 += x * x;
    m3 += x * x * x;
    m4 += x * x * x * x;
    beyond1 += std::abs(x) > 1.0;
    beyond3 += std::abs(x) > 3.0;
    beyond_r += std::abs(x) > 3.5;
  }
  m1 /= kN, m2 /= kN, m3 /= kN, m4 /= kN;
  EXPECT_NEAR(m1, 0.0, 5 * 1e-3);    // standard error 1e-3
  EXPECT_NEAR(m2, 1.0, 5 * 1.4e-3);  // √2/√N
  EXPECT_NEAR(m3, 0.0, 5 * 3.9e-3);  // √15/√N
  EXPECT_NEAR(m4, 3.0, 5 * 9.8e-3);  // √96/√N
  EXPECT_NEAR(beyond1 / double(kN), 0.317311, 5 * 4.7e-4);
  EXPECT_NEAR(beyond3 / double(kN), 0.0026998, 5 * 5.2e-5);
  EXPECT_NEAR(beyond_r / double(kN), 4.6525e-4, 5 * 2.2e-5);  // the tail beyond the Ziggurat's r
}

TEST(GaussianNoise, SameSeedSameSequence) {
  GaussianNoise a(5), b(5), c(6);
  bool differs = false;
  for (int k = 0; k < 100; ++k) {
    const double x = a();
    EXPECT_EQ(x, b());
    differs = differs || x != c();
  }
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace rpem::sim
