// A window's temperatures when a sensor reads on few of its cycles (sim/cycle_average.hpp): the mean of the
// readings it has, NaN with none — the native protocol's temperature frame comes every 100 ms, a window lasts
// a few ms, so most windows have no reading and one has a single one.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rpem/sim/cycle_average.hpp"

namespace rpem::sim {
namespace {

constexpr double kNoReading = std::numeric_limits<double>::quiet_NaN();

ControlCycle cycle(std::int64_t k, double winding_C, double coolant_C) {
  ControlCycle c;
  c.t_ns = 125'000 * k;
  c.end_ns = 125'000 * (k + 1);
  c.i_dq_A = {static_cast<double>(k), 2.0};
  c.u_dq_V = {3.0, 4.0};
  c.omega_el_rad_s = 100.0;
  c.u_dc_V = 48.0;
  c.t_winding_C = winding_C;
  c.t_magnet_C = kNoReading;
  c.t_coolant_C = coolant_C;
  return c;
}

TEST(CycleAccumulator, ATemperatureIsTheMeanOfTheReadingsTheWindowHas) {
  CycleAccumulator sums;
  sums.add(cycle(0, kNoReading, kNoReading));
  sums.add(cycle(1, 61.0, kNoReading));
  sums.add(cycle(2, kNoReading, 30.5));
  sums.add(cycle(3, 62.0, kNoReading));
  const core::AveragedSample w = sums.read_reset();
  EXPECT_DOUBLE_EQ(w.t_winding_C, 61.5);  // (61 + 62) / 2: the two cycles that read it
  EXPECT_DOUBLE_EQ(w.t_coolant_C, 30.5);  // its one reading
  EXPECT_TRUE(std::isnan(w.t_magnet_C));  // no reading in the window
  // The electrical means still run over all four cycles.
  EXPECT_DOUBLE_EQ(w.i_dq_A[0], 1.5);  // (0 + 1 + 2 + 3) / 4
  EXPECT_EQ(w.t_start_ns, 0);
  EXPECT_EQ(w.t_ns, 500'000);
}

TEST(CycleAccumulator, AWindowWithoutAReadingHasNoneAndTheNextStartsAfresh) {
  CycleAccumulator sums;
  sums.add(cycle(0, 70.0, 25.0));
  (void)sums.read_reset();
  sums.add(cycle(1, kNoReading, kNoReading));
  sums.add(cycle(2, kNoReading, kNoReading));
  const core::AveragedSample w = sums.read_reset();
  EXPECT_TRUE(std::isnan(w.t_winding_C));  // the previous window's reading is not carried over
  EXPECT_TRUE(std::isnan(w.t_coolant_C));
  EXPECT_DOUBLE_EQ(w.u_dc_V, 48.0);
}

}  // namespace
}  // namespace rpem::sim
