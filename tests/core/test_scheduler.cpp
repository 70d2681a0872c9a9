#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rpem/core/scheduler.hpp"

namespace rpem::core {
namespace {

TEST(Scheduler, EqGainScheduleWithStrictBoundaries) {
  const SchedulerConfig c{0.1, 0.01};
  struct Case {
    double n;
    bool psi, rs;
  };
  for (const Case k : {Case{0.0, false, true}, Case{0.0099, false, true}, Case{-0.0099, false, true},
                       Case{0.01, false, false}, Case{-0.05, false, false}, Case{0.1, false, false},
                       Case{-0.1, false, false}, Case{0.1001, true, false}, Case{-0.8, true, false}}) {
    const Schedule s = schedule(c, k.n);
    EXPECT_EQ(s.psi_m, k.psi) << k.n;
    EXPECT_EQ(s.r_s, k.rs) << k.n;
  }
}

TEST(Scheduler, ZeroesTheRowsOfInactiveParameters) {
  Mat2 l;
  l << 1, 2, 3, 4;
  Mat2 only_psi = l;
  apply_schedule({true, false}, only_psi);
  EXPECT_EQ(only_psi.row(kPsiM), l.row(kPsiM));
  EXPECT_EQ(only_psi.row(kRs).norm(), 0.0);
  Mat2 only_rs = l;
  apply_schedule({false, true}, only_rs);
  EXPECT_EQ(only_rs.row(kPsiM).norm(), 0.0);
  EXPECT_EQ(only_rs.row(kRs), l.row(kRs));
}

TEST(Projection, ClampsToTheBoxAndReportsWhich) {
  const ParameterBounds b{Vec2(0.5, 0.02), Vec2(1.5, 0.1)};
  Vec2 inside(1.0, 0.05);
  EXPECT_EQ(project(b, inside), 0);
  EXPECT_EQ(inside, Vec2(1.0, 0.05));
  Vec2 low_psi(0.2, 0.05);
  EXPECT_EQ(project(b, low_psi), 1U << kPsiM);
  EXPECT_EQ(low_psi, Vec2(0.5, 0.05));
  Vec2 both(9.0, -1.0);
  EXPECT_EQ(project(b, both), (1U << kPsiM) | (1U << kRs));
  EXPECT_EQ(both, Vec2(1.5, 0.02));
}

TEST(Scheduler, ARowThatMayNotAdaptIsZeroEvenIfItsGainIsNotFinite) {
  Mat2 gain;
  gain << std::nan(""), 2.0, 3.0, std::numeric_limits<double>::infinity();
  Schedule s;
  s.psi_m = false;
  s.r_s = true;
  apply_schedule(s, gain);
  EXPECT_EQ(gain(kPsiM, 0), 0.0);
  EXPECT_EQ(gain(kPsiM, 1), 0.0);
  EXPECT_EQ(gain(kRs, 0), 3.0);
  EXPECT_TRUE(std::isinf(gain(kRs, 1)));
}

}  // namespace
}  // namespace rpem::core
