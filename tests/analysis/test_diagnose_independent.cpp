// rpem diagnose on data that does not share its model forms (docs/diagnose.md, "Tests on independent
// data"; issue 10 item 8), one case of each kind (label diagnose): a null, a single, a pair and a triple;
// the many-seed study is test_diagnose_study (label slow).
#include <gtest/gtest.h>

#include "support/independent_case.hpp"

namespace rpem {
namespace {

TEST(IndependentData, OneCasePerKind) {
  // A null, a single, a pair and a triple (seeds chosen to cover dead time, delay and a flux harmonic).
  for (std::uint64_t seed : {1U, 2U, 6U, 10U}) {
    const test::IndependentOutcome out = test::run_independent_case(test::independent_case_of(seed, test::kIndependentDuration_s));
    std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
    EXPECT_TRUE(out.correct) << out.detail;
  }
}

TEST(IndependentData, ACommandDelayOfWholePeriodsIsToldFromAnAngleOffset) {
  // The most common drive delay, two whole control periods, together with a 3° encoder offset: at one
  // speed they would both turn the voltage; the profile's speeds tell them apart (issue 10 item 3).
  for (double periods : {1.0, 2.0, 2.5}) {
    test::IndependentCase c{{"delay", "theta_offset"}, 31, test::kIndependentDuration_s,
                            {{"delay.periods", periods}, {"theta_offset.offset_rad", 0.05236}}};
    const test::IndependentOutcome out = test::run_independent_case(c);
    std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
    EXPECT_TRUE(out.correct) << out.detail;
  }
}

}  // namespace
}  // namespace rpem
