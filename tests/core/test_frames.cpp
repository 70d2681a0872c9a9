#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rpem/core/frames.hpp"
#include "support/seed.hpp"

namespace rpem::core {
namespace {

TEST(Frames, ClarkeIsAmplitudeInvariant) {
  // GIVEN a balanced set of amplitude 2 at angle φ THEN the αβ vector has length 2 and angle φ.
  const double phi = 0.7;
  const Vec3 abc(2.0 * std::cos(phi), 2.0 * std::cos(phi - 2.0 * kPi / 3.0), 2.0 * std::cos(phi + 2.0 * kPi / 3.0));
  const Vec2 ab = clarke(abc);
  EXPECT_NEAR(ab[0], 2.0 * std::cos(phi), 1e-14);
  EXPECT_NEAR(ab[1], 2.0 * std::sin(phi), 1e-14);
}

TEST(Frames, ParkAlignsTheRotatingVector) {
  const double theta = 1.1;
  const Vec2 ab(std::cos(theta), std::sin(theta));
  const Vec2 dq = park(ab, Rotation::of(theta));
  EXPECT_NEAR(dq[0], 1.0, 1e-15);
  EXPECT_NEAR(dq[1], 0.0, 1e-15);
}

TEST(Frames, RoundTripsOnRandomInputs) {
  std::mt19937_64 rng(test::test_seed(11));
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int k = 0; k < 1000; ++k) {
    const Vec2 ab(u(rng), u(rng));
    const Rotation r = Rotation::of(u(rng));
    EXPECT_LT((inverse_park(park(ab, r), r) - ab).norm(), 1e-12);
    EXPECT_LT((clarke(inverse_clarke(ab)) - ab).norm(), 1e-12);
    // A zero-sequence component never reaches αβ.
    const Vec3 abc = inverse_clarke(ab) + Vec3::Constant(u(rng));
    EXPECT_LT((clarke(abc) - ab).norm(), 1e-12);
  }
}

TEST(Frames, WrapAngle) {
  EXPECT_NEAR(wrap_angle(3.0 * kPi + 0.1), -kPi + 0.1, 1e-12);
  EXPECT_NEAR(wrap_angle(-0.25), -0.25, 1e-15);
}

TEST(Frames, SmallRotationMatchesSinCosToRoundOff) {
  // The Taylor series' first omitted terms bound the error: x^10/10! and x^9/9! < 3e-15 for |x| <= 0.1.
  for (double x = -0.1; x <= 0.1; x += 0.001) {
    const Rotation r = small_rotation(x);
    EXPECT_NEAR(r.cos, std::cos(x), 3e-15) << x;
    EXPECT_NEAR(r.sin, std::sin(x), 3e-15) << x;
  }
}

TEST(Frames, RotationTrackerFollowsAnAngleToRoundOff) {
  // A wrapped angle turning at 0.03 rad per call, with a jump beyond the increment range and a reset:
  // every result within 1e-13 of libm's (kExactEvery compositions of ≤ 3e-15 each, plus round-off).
  RotationTracker tracker;
  double theta = 3.0;
  for (int k = 0; k < 1000; ++k) {
    theta = wrap_angle(theta + (k == 500 ? 1.0 : 0.03));  // crosses ±π repeatedly
    if (k == 700) tracker.reset();
    const Rotation r = tracker.at(theta);
    ASSERT_NEAR(r.cos, std::cos(theta), 1e-13) << k;
    ASSERT_NEAR(r.sin, std::sin(theta), 1e-13) << k;
  }
}

}  // namespace
}  // namespace rpem::core
