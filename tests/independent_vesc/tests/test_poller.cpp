// VESC Tool's reads (README "Reads"): the mean row rate the link allows, rows 60 ms to more than a second apart,
// one request outstanding at a time, and a lost reply silencing the log for VESC Tool's one-second time-out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "indep_vesc/poller.hpp"

namespace indep::vesc {
namespace {

std::vector<double> logged_intervals(const std::vector<ReadEvent>& reads) {
  std::vector<double> t;
  for (const ReadEvent& r : reads) {
    if (r.logged) t.push_back(r.t_reply_s);
  }
  std::sort(t.begin(), t.end());
  std::vector<double> d;
  for (std::size_t k = 1; k < t.size(); ++k) d.push_back(t[k] - t[k - 1]);
  return d;
}

TEST(IndepVescPoller, MeanRowRateIsTheLinksAndIntervalsSpreadAsInTheField) {
  for (const double rate : {8.0, 11.0, 15.0}) {
    Poller p;
    p.rate_Hz = rate;
    const std::vector<ReadEvent> reads = poll_schedule(p, 2000.0, 7);
    const std::vector<double> d = logged_intervals(reads);
    double mean = 0.0;
    for (double x : d) mean += x;
    mean /= static_cast<double>(d.size());
    // The round trip's median is solved for the mean interval (rtt_median_s); what is left is the spread of
    // ~20 000 rows and the ticks' phase against the round trip.
    EXPECT_NEAR(1.0 / mean, rate, 0.03 * rate) << "rate " << rate;
    const double longest = *std::max_element(d.begin(), d.end());
    EXPECT_GT(longest, 0.9) << "a lost reply or a stall leaves a gap near VESC Tool's 1 s time-out";
    EXPECT_LT(longest, 1.0 + p.stall_max_s + 0.2);
    std::vector<double> sorted = d;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_GT(sorted[sorted.size() / 100], 0.04) << "1st percentile";
  }
}

TEST(IndepVescPoller, OneRequestAtATimeAndTheTimeOutAfterALoss) {
  Poller p;
  p.loss_probability = 0.05;
  p.stall_probability = 0.0;
  const std::vector<ReadEvent> reads = poll_schedule(p, 600.0, 3);
  int lost = 0;
  for (std::size_t k = 0; k + 1 < reads.size(); ++k) {
    ASSERT_LT(reads[k].t_read_s, reads[k + 1].t_read_s);
    if (reads[k].logged) {
      // Without stalls the next request leaves only after this reply came back.
      EXPECT_GT(reads[k + 1].t_read_s, reads[k].t_reply_s) << k;
    } else {
      ++lost;
      // The reply was lost: the next request waits for the 1 s time-out (counted by the 10 ms timer).
      EXPECT_GT(reads[k + 1].t_request_s - reads[k].t_request_s, 0.99) << k;
    }
  }
  EXPECT_GT(lost, 5);
}

TEST(IndepVescPoller, DeterministicPerSeed) {
  Poller p;
  const auto a = poll_schedule(p, 60.0, 5), b = poll_schedule(p, 60.0, 5), c = poll_schedule(p, 60.0, 6);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k].t_read_s, b[k].t_read_s);
  EXPECT_NE(a.front().t_read_s, c.front().t_read_s);
}

}  // namespace
}  // namespace indep::vesc
