#include <gtest/gtest.h>

#include "rpem/daemon/latency_histogram.hpp"

namespace rpem::daemon {
namespace {

TEST(LatencyHistogram, StatisticsOfAKnownSet) {
  LatencyHistogram h;
  for (int k = 1; k <= 100; ++k) h.add(k - 0.5);  // 0.5, 1.5, …, 99.5 µs
  h.add(20'000.0);                                // beyond the bins
  EXPECT_EQ(h.count(), 101);
  EXPECT_DOUBLE_EQ(h.min(), 0.5);
  EXPECT_DOUBLE_EQ(h.max(), 20'000.0);
  EXPECT_NEAR(h.mean(), (5000.0 + 20'000.0) / 101.0, 1e-9);
  EXPECT_DOUBLE_EQ(h.percentile(0.5), 51.0);  // the 51st value lies in bin [50, 51)
  EXPECT_DOUBLE_EQ(h.percentile(0.99), 100.0);
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 20'000.0);
  h.reset();
  EXPECT_EQ(h.count(), 0);
  EXPECT_EQ(h.percentile(0.99), 0.0);
}

// Every value from 1 µs to 2²⁷ µs lies in a bin whose edges hold it, at most 1/64 of the lower edge wide (1.6 %).
TEST(WideLatencyHistogram, EachBinHoldsItsValuesWithinOneSixtyFourthOfAnOctave) {
  for (double us = 1.0; us < 0x1p27; us *= 1.0037) {
    const int b = OctaveBins::of(us);
    ASSERT_GT(b, 0) << us;
    ASSERT_LT(b, OctaveBins::kOverflow) << us;
    const double lower = OctaveBins::upper_edge(b - 1), upper = OctaveBins::upper_edge(b);
    EXPECT_LE(lower, us) << us;
    EXPECT_LT(us, upper) << us;
    EXPECT_LE(upper / lower - 1.0, 1.0 / 64.0 + 1e-15) << us;
  }
  EXPECT_EQ(OctaveBins::of(0.25), 0);
  EXPECT_EQ(OctaveBins::of(1.0), 1);
  EXPECT_EQ(OctaveBins::of(0x1p27), OctaveBins::kOverflow);
}

// Latencies of a VESC polled at 10 Hz (100-200 ms: a poll period held, then the estimate's publication) and of a
// drive streaming at 8 kHz (2-4 ms): each percentile is the true one to the bin, within 1.6 % above it, where the
// 1-µs histogram reads anything past 10 ms as the maximum.
TEST(WideLatencyHistogram, PercentilesAtEveryScaleAreWithinTheBinsWidth) {
  for (const double scale_us : {2'000.0, 100'000.0}) {
    WideLatencyHistogram h;
    LatencyHistogram narrow;
    for (int k = 0; k < 1000; ++k) {
      const double us = scale_us * (1.0 + (k + 0.5) / 1000.0);  // uniform over [scale, 2·scale)
      h.add(us);
      narrow.add(us);
    }
    for (const double q : {0.5, 0.99}) {
      const double truth = scale_us * (1.0 + (q * 1000.0 - 0.5) / 1000.0);  // the ⌊q·n + ½⌋-th value
      EXPECT_GE(h.percentile(q), truth) << scale_us << " q " << q;
      EXPECT_LE(h.percentile(q), truth * (1.0 + 1.0 / 64.0)) << scale_us << " q " << q;
    }
    if (scale_us > 10'000.0) {
      EXPECT_EQ(narrow.percentile(0.5), narrow.max());
    }
  }
  WideLatencyHistogram h;
  h.add(0.4);
  h.add(3e8);                                // beyond 2²⁷ µs: the overflow bin, read as the max
  EXPECT_DOUBLE_EQ(h.percentile(0.5), 1.0);  // the upper edge of [0, 1) µs
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 3e8);
  EXPECT_NEAR(h.mean(), (0.4 + 3e8) / 2.0, 1e-6);
}

}  // namespace
}  // namespace rpem::daemon
