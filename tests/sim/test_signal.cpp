#include <gtest/gtest.h>

#include <cmath>

#include "rpem/sim/signal.hpp"

namespace rpem::sim {
namespace {

TEST(Signal, StepRampAndThermalEvents) {
  Signal s(10.0);
  s.add({1.0, EventKind::kStep, 8.0, 0.0});
  s.add({2.0, EventKind::kRamp, 12.0, 2.0});
  s.add({5.0, EventKind::kThermal, 20.0, 3.0});
  EXPECT_DOUBLE_EQ(s.at(0.0), 10.0);
  EXPECT_DOUBLE_EQ(s.at(0.999), 10.0);
  EXPECT_DOUBLE_EQ(s.at(1.0), 8.0);
  EXPECT_DOUBLE_EQ(s.at(3.0), 10.0);  // half-way up the ramp from 8 to 12
  EXPECT_DOUBLE_EQ(s.at(4.5), 12.0);
  EXPECT_NEAR(s.at(8.0), 20.0 + (12.0 - 20.0) * std::exp(-1.0), 1e-12);
}

TEST(Signal, ThermalEventStartsFromWhereARampWasInterrupted) {
  Signal s(0.0);
  s.add({0.0, EventKind::kRamp, 10.0, 10.0});
  s.add({5.0, EventKind::kThermal, 0.0, 1.0});
  EXPECT_DOUBLE_EQ(s.at(4.0), 4.0);
  EXPECT_NEAR(s.at(6.0), 5.0 * std::exp(-1.0), 1e-12);
}

}  // namespace
}  // namespace rpem::sim
