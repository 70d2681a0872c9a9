// rpem diagnose over many seeds (label slow; docs/diagnose.md, "Hidden-effect tests"): each seed draws
// the effect's magnitude (and phase, sign, whether temperatures are logged); the catalogue, null cases,
// two-effect cases and the measured flux maps take turns. At least 95 % must be right, and no null case
// may name an effect. Every case prints one line, so a failure can be replayed from its seed.
#include <gtest/gtest.h>

#include <cstdlib>

#include "support/hidden_effect_case.hpp"

namespace rpem {
namespace {

TEST(HiddenEffectSeeds, AtLeast95PercentRightAndNoFalsePositive) {
  const std::vector<std::vector<std::string>> cycle = {{},
                                                       {"deadtime"},
                                                       {"theta_offset"},
                                                       {"current_offset"},
                                                       {"current_gain"},
                                                       {"rs_drift"},
                                                       {"psim_drift"},
                                                       {"delay"},
                                                       {"iron_loss"},
                                                       {},
                                                       {"deadtime", "theta_offset"},
                                                       {"rs_drift", "current_offset"},
                                                       {"iron_loss", "current_gain"}};
  const char* env = std::getenv("RPEM_DIAGNOSE_SEEDS");
  const int seeds = env ? std::atoi(env) : 60;
  int right = 0, nulls = 0, false_positives = 0;
  for (int k = 0; k < seeds; ++k) {
    test::HiddenCase c;
    c.seed = 5000 + static_cast<std::uint64_t>(k);
    c.effects = cycle[static_cast<std::size_t>(k) % cycle.size()];
    if (k % 20 == 19) {  // the measured flux maps: the map itself is what is hidden
      c.profile = k % 40 == 19 ? "beckhoff400" : "beckhoff800";
      c.effects.clear();
    }
    const test::CaseOutcome out = test::run_hidden_case(c);
    right += out.correct ? 1 : 0;
    nulls += out.null_case ? 1 : 0;
    false_positives += out.false_positive ? 1 : 0;
    std::printf("%s %s\n", out.correct ? "right" : "WRONG", out.detail.c_str());
    std::fflush(stdout);
  }
  std::printf("%d of %d right (%.1f %%); %d null cases, %d false positives\n", right, seeds, 100.0 * right / seeds, nulls,
              false_positives);
  EXPECT_GE(right, static_cast<int>(std::ceil(0.95 * seeds)));
  EXPECT_EQ(false_positives, 0);
  EXPECT_GT(nulls, 0);
}

}  // namespace
}  // namespace rpem
