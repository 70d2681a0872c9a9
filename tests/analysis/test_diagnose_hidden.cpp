// rpem diagnose finds the effect hidden in a simulated drive log (docs/diagnose.md, "Hidden-effect
// tests"): the fast label runs one seed per catalogue effect, null cases, two-effect cases and the
// measured Beckhoff flux maps; test_diagnose_seeds (label slow) runs many seeds.
#include <gtest/gtest.h>

#include "support/hidden_effect_case.hpp"
#include "support/seed.hpp"

namespace rpem {
namespace {

class HiddenEffect : public ::testing::TestWithParam<test::HiddenCase> {};

TEST_P(HiddenEffect, IsNamedWithItsParameterWithin15Percent) {
  test::HiddenCase c = GetParam();
  c.seed = test::test_seed(c.seed);
  const test::CaseOutcome out = test::run_hidden_case(c);
  std::printf("%s\n", out.detail.c_str());
  EXPECT_TRUE(out.correct) << out.detail;
  EXPECT_FALSE(out.false_positive) << out.detail;
}

std::string name_of(const ::testing::TestParamInfo<test::HiddenCase>& p) {
  std::string n = p.param.profile;
  for (const auto& e : p.param.effects) n += "_" + e;
  if (p.param.effects.empty()) n += "_none";
  return n + "_" + std::to_string(p.param.seed);
}

INSTANTIATE_TEST_SUITE_P(
    OnePerEffect, HiddenEffect,
    ::testing::Values(test::HiddenCase{"bench", {}, 101}, test::HiddenCase{"bench", {}, 102},
                      test::HiddenCase{"bench", {"deadtime"}, 103}, test::HiddenCase{"bench", {"theta_offset"}, 104},
                      test::HiddenCase{"bench", {"current_offset"}, 105}, test::HiddenCase{"bench", {"current_gain"}, 106},
                      test::HiddenCase{"bench", {"rs_drift"}, 107}, test::HiddenCase{"bench", {"rs_drift"}, 108},
                      test::HiddenCase{"bench", {"psim_drift"}, 109}, test::HiddenCase{"bench", {"delay"}, 110},
                      test::HiddenCase{"bench", {"iron_loss"}, 111},
                      test::HiddenCase{"bench", {"deadtime", "theta_offset"}, 112},
                      test::HiddenCase{"bench", {"rs_drift", "current_offset"}, 113},
                      test::HiddenCase{"beckhoff400", {}, 114}, test::HiddenCase{"beckhoff800", {}, 115}),
    name_of);

}  // namespace
}  // namespace rpem
