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

}  // namespace
}  // namespace rpem::daemon
