// rpem diagnose on data that does not share its model forms (docs/diagnose.md, "Tests on independent
// data"; issue 10 item 8), one case of each kind (label diagnose): a null, a single, a pair and a triple;
// the many-seed study is test_diagnose_study (label slow).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "support/independent_case.hpp"

namespace rpem {
namespace {

TEST(IndependentData, OneCasePerKind) {
  // A null, a single, a pair and a triple (seeds chosen to cover dead time, delay and a flux harmonic).
  for (std::uint64_t seed : {1U, 2U, 6U, 10U}) {
    const test::IndependentOutcome out =
        test::run_independent_case(test::independent_case_of(seed, test::kIndependentDuration_s));
    std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
    EXPECT_TRUE(out.correct) << out.detail;
  }
}

TEST(IndependentData, ACommandDelayOfWholePeriodsIsToldFromAnAngleOffset) {
  // The most common drive delay, two whole control periods, together with a 3° encoder offset: at one
  // speed they would both turn the voltage; the profile's speeds tell them apart (issue 10 item 3).
  for (double periods : {1.0, 2.0, 2.5}) {
    test::IndependentCase c{{"delay", "theta_offset"},
                            31,
                            test::kIndependentDuration_s,
                            {{"delay.periods", periods}, {"theta_offset.offset_rad", 0.05236}}};
    const test::IndependentOutcome out = test::run_independent_case(c);
    std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
    EXPECT_TRUE(out.correct) << out.detail;
  }
}

TEST(IndependentData, ACommandDelayIsFoundBesideOtherEffectsOnAMachineOffItsConfiguration) {
  // A whole-period delay among other effects (issue 10 item 3): with a dead time, which fitted without the
  // delay takes part of its residual; with ψm and R_s well off the configuration; with a θ offset too.
  // The case is right only when exactly the hidden effects are named (so no cross- or L_d saturation
  // standing in for the delay), each within 15 %, and the calibrated ψm and R_s within 2 % and 5 %.
  const std::vector<test::IndependentCase> cases = {
      {{"deadtime", "delay"}, 45, test::kIndependentDuration_s, {{"delay.periods", 1.0}}},
      {{"deadtime", "delay"},
       42,
       test::kIndependentDuration_s,
       {{"delay.periods", 2.0}, {"deadtime.t_dead_s", 2e-6}, {"draw.psi_m_rel", -0.05}, {"draw.r_s_rel", 0.18}}},
      {{"deadtime", "delay", "theta_offset"},
       43,
       test::kIndependentDuration_s,
       {{"delay.periods", 2.0}, {"theta_offset.offset_rad", 0.05236}}},
      {{"delay"},
       44,
       test::kIndependentDuration_s,
       {{"delay.periods", 1.0}, {"draw.psi_m_rel", 0.06}, {"draw.r_s_rel", -0.2}}},
  };
  const char* only = std::getenv("RPEM_INDEPENDENT_ONLY_SEED");  // to replay one case
  for (const test::IndependentCase& c : cases) {
    if (only && std::to_string(c.seed) != only) continue;
    const test::IndependentOutcome out = test::run_independent_case(c);
    std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
    EXPECT_TRUE(out.correct) << out.detail;
    EXPECT_EQ(out.detail.find("cross_saturation"), std::string::npos) << out.detail;
  }
}

TEST(IndependentData, ConstantsAMissingEffectHidAreFreedInTheCandidatesFits) {
  // Issue 10's table row as a user ran it (indep_drive_log --seed 7 --duration-s 20, its own profile):
  // ψm −6 %, R_s +18 %, a 1.5 µs dead time and a 0.1 A offset on phase a. Next to the missing dead time the
  // calibration cannot identify ψm and R_s and leaves them configured; a dead time fitted under those wrong
  // constants gains on the held-out blocks but the blocks disagree, and the diagnosis said "effects: none"
  // at 65 times the noise floor. The second look (docs/diagnose.md, "Constants a missing effect hid")
  // fits the leading candidates again with those constants free.
  test::IndependentCase c{{"deadtime", "current_offset"},
                          7,
                          20.0,
                          {{"deadtime.t_dead_s", 1.5e-6},
                           {"current_offset.a_A", 0.1},
                           {"current_offset.b_A", 0.0},  // the seed's draw put one on b; the row has a only
                           {"current_offset.c_A", 0.0},
                           {"draw.psi_m_rel", -0.06},
                           {"draw.r_s_rel", 0.18},
                           {"draw.l_d_rel", 0.0},
                           {"draw.l_q_rel", 0.0}}};
  c.generator_profile = true;
  const test::IndependentOutcome out = test::run_independent_case(c);
  std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
  EXPECT_TRUE(out.correct) << out.detail;
}

}  // namespace
}  // namespace rpem
