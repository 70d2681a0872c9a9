// The project's assertion (rpem/core/assert.hpp): where assertions are on it aborts naming the file, the
// line, the condition and why; where they are off it does not evaluate the condition. This file forces
// them on whatever the build (NDEBUG or not), test_assert_off.cpp forces them off; neither includes
// anything else whose definition depends on the switch.
#undef RPEM_ASSERTIONS
#define RPEM_ASSERTIONS 1
#include "rpem/core/assert.hpp"

#include <gtest/gtest.h>

namespace rpem::core {

int evaluations_with_assertions_off();  // test_assert_off.cpp

namespace {

int twice(int x) {
  RPEM_ASSERT(x >= 0, "callers pass counts");
  return 2 * x;
}

TEST(Assert, AViolatedInvariantAbortsNamingWhereAndWhy) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EQ(twice(3), 6);
  EXPECT_DEATH((void)twice(-1), "test_assert\\.cpp:[0-9]+: invariant violated: x >= 0 \\(callers pass counts\\)");
}

TEST(Assert, AHoldingInvariantEvaluatesItsConditionOnce) {
  int evaluated = 0;
  RPEM_ASSERT(++evaluated == 1, "evaluated once");
  EXPECT_EQ(evaluated, 1);
}

TEST(Assert, OffTheConditionIsNotEvaluated) { EXPECT_EQ(evaluations_with_assertions_off(), 0); }

}  // namespace
}  // namespace rpem::core
