// SpeedErrorDelay: each window of rpemd's VESC source waits for the next reply, whose change of acceleration shows a
// change inside the window that the window's own end read does not yet (docs/derivations.md §13, "… where the
// acceleration changes"). Against a PLL run per control cycle on a stop (support/pll_reads.hpp): the error stated
// covers the rebuild's, where the end read alone would state a fraction of it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <vector>

#include "rpem/core/reported_speed.hpp"
#include "rpem/daemon/speed_error_delay.hpp"
#include "support/pll_reads.hpp"

namespace {

using rpem::core::AveragedSample;
using rpem::core::PllGains;
using rpem::core::SpeedRead;
using rpem::daemon::SpeedErrorDelay;
using rpem::test::PllWindow;

constexpr PllGains kPll{rpem::test::kPllKp, rpem::test::kPllKi};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

AveragedSample window_between(std::int64_t start_ns, std::int64_t end_ns, double omega_rad_s) {
  AveragedSample s;
  s.t_start_ns = start_ns;
  s.t_ns = end_ns;
  s.omega_el_rad_s = omega_rad_s;
  return s;
}

struct Judged {
  std::vector<AveragedSample> released;  // in order; released[j] is window j + 1 of the run (window 0 opens it)
  std::vector<double> end_read_only;     // the error its own end read states (the judgement before the delay)
};

/// The PLL's windows through the delay as rpemd's source passes them: each reply's change first, then its window.
Judged judge(const std::vector<PllWindow>& w) {
  const auto read = [&](std::size_t j) { return SpeedRead{std::llround(w[j].t_s * 1e9), w[j].at_read}; };
  SpeedErrorDelay delay(kPll);
  Judged out;
  for (std::size_t k = 1; k < w.size(); ++k) {
    const double change = k >= 2 ? rpem::core::read_accel_change_rad_s2(read(k - 2), read(k - 1), read(k)) : kNaN;
    AveragedSample due;
    if (delay.on_read(change, due)) out.released.push_back(due);
    const AveragedSample window = window_between(read(k - 1).t_ns, read(k).t_ns, w[k].rebuilt);
    out.end_read_only.push_back(std::isfinite(change)
                                    ? rpem::core::window_mean_speed_error_rad_s(
                                          kPll, change, rpem::core::to_seconds(window.t_ns - window.t_start_ns))
                                    : 0.0);
    delay.hold(window);
  }
  return out;
}

// A stop at constant braking current (seed 1's of tests/independent_vesc: 3 400 rad/s to standstill in 0.31 s) that
// begins at five places inside a window, read 1 s to 5 ms apart (poll rates of 1 to 200 Hz). Judged by both ends, the
// error stated covers the rebuild's (and the loop's 1.5-cycle lag) as the log's reader's does (test_core's
// ReportedSpeed.TheErrorTheReadsShowCovers…: at 56 and 90 ms within 1/0.6 of it, up to 11 rad/s short). Judged by
// its end read alone — rpemd before the delay — it falls up to 15, 31 and 178 rad/s short at 56, 90 and 240 ms
// (measured 2026-12-01); at 5 ms and 1 s either judgement covers.
TEST(SpeedErrorDelay, AStopsFirstWindowIsJudgedByTheReadAfterIt) {
  constexpr double a = 11000.0;
  constexpr double kLoopLag = 1.5 * a * rpem::test::kPllCycleS, kErrorFloor = 20.0 * a * rpem::test::kPllCycleS;
  for (const int read_cycles : {12500, 3000, 1125, 700, 62}) {
    const double h = read_cycles * rpem::test::kPllCycleS;
    const bool between = read_cycles == 700 || read_cycles == 1125;
    double end_only_short = 0.0;  // the most the end read alone falls short, over the stop's places
    for (const double phase : {0.05, 0.2, 0.5, 0.8, 0.95}) {
      const double t0 = std::ceil(2.0 / h) * h + phase * h;  // after the PLL's start-up
      const auto stop = [t0](double t) { return t < t0 ? 3400.0 : std::max(0.0, 3400.0 - a * (t - t0)); };
      const std::vector<PllWindow> w = rpem::test::run_pll(stop, t0 + 2.0, read_cycles);
      const Judged j = judge(w);
      ASSERT_EQ(j.released.size() + 1, j.end_read_only.size());  // the newest window is still held
      double beyond = 0.0, least_ratio = 1e300;
      for (std::size_t r = 0; r < j.released.size(); ++r) {
        const std::size_t k = r + 1;
        if (w[k].t_s < 0.3) continue;  // the PLL's start-up
        const AveragedSample& s = j.released[r];
        EXPECT_EQ(s.omega_el_rad_s, w[k].rebuilt);  // the window goes on as it came, its error set
        EXPECT_GE(s.omega_el_error_rad_s, j.end_read_only[r]);
        const double error = std::abs(w[k].rebuilt - w[k].true_mean);
        beyond = std::max(beyond, error - s.omega_el_error_rad_s - kLoopLag);
        end_only_short = std::max(end_only_short, error - j.end_read_only[r] - kLoopLag);
        if (error > kErrorFloor) least_ratio = std::min(least_ratio, s.omega_el_error_rad_s / error);
      }
      std::printf("[ speed    ] stop at %.2f of a %.4f s window: beyond E by %.2f rad/s at most, E/error ≥ %.2f\n", phase, h,
                  beyond, least_ratio < 1e300 ? least_ratio : std::nan(""));
      if (!between) {
        EXPECT_LE(beyond, 0.0) << "h " << h << ", phase " << phase;
      }
      if (least_ratio < 1e300) {
        EXPECT_GE(least_ratio, between ? 0.6 : 0.9) << "h " << h << ", phase " << phase;
      }
    }
    std::printf("[ speed    ] h %.4f s: the end read alone falls short by %.2f rad/s at most\n", h, end_only_short);
    if (read_cycles >= 700 && read_cycles <= 3000) {
      EXPECT_GT(end_only_short, 10.0) << "h " << h << ": the delay is what covers the stop's first window";
    }
  }
}

// The error's noise is the latest kAccelChangeRunReads changes' — the next reply's among them — through the same
// error law; a reply that closes no window (a gap, NaN) releases the one held, judged by its own end read alone.
TEST(SpeedErrorDelay, ItsNoiseIsTheLatestChangesAndAGapReleasesTheWindowByItsOwnRead) {
  SpeedErrorDelay delay(kPll);
  AveragedSample due;
  constexpr std::int64_t kH = 100'000'000;  // 100 ms windows
  const double h = 0.1;
  // 20 replies whose changes alternate ±c: σ = 1.4826·c.
  constexpr double c = 40.0;
  std::int64_t t = 0;
  for (int k = 0; k < 20; ++k, t += kH) {
    const double change = k % 2 == 0 ? c : -c;
    const bool released = delay.on_read(change, due);
    EXPECT_EQ(released, k > 0);
    delay.hold(window_between(t - kH, t, 100.0));
  }
  // The next reply shows a large change: the held window takes it, its noise the run's.
  ASSERT_TRUE(delay.on_read(5000.0, due));
  EXPECT_DOUBLE_EQ(due.omega_el_error_rad_s, rpem::core::window_mean_speed_error_rad_s(kPll, 5000.0, h));
  EXPECT_NEAR(due.omega_el_error_noise_rad_s, rpem::core::window_mean_speed_error_rad_s(kPll, 1.4826022185056018 * c, h),
              1e-12);
  delay.hold(window_between(t - kH, t, 100.0));
  // A gap: this reply closed no window (NaN); the held one goes on, judged by the change its own end read showed.
  ASSERT_TRUE(delay.on_read(kNaN, due));
  EXPECT_DOUBLE_EQ(due.omega_el_error_rad_s, rpem::core::window_mean_speed_error_rad_s(kPll, 5000.0, h));
  EXPECT_FALSE(delay.holding());
  EXPECT_FALSE(delay.on_read(c, due));  // nothing held: nothing released
}

// The first windows (fewer than three reads: no change at either end) state no error; a speed that is not a PLL's
// (gains not given) is the window's own mean and goes on untouched.
TEST(SpeedErrorDelay, NoChangeAtEitherEndOrNoPllStatesNoError) {
  SpeedErrorDelay delay(kPll);
  AveragedSample due;
  EXPECT_FALSE(delay.on_read(kNaN, due));
  delay.hold(window_between(0, 5'000'000, 10.0));
  ASSERT_TRUE(delay.on_read(kNaN, due));
  EXPECT_EQ(due.omega_el_error_rad_s, 0.0);
  EXPECT_EQ(due.omega_el_error_noise_rad_s, 0.0);

  SpeedErrorDelay own(PllGains{});
  own.hold(window_between(0, 5'000'000, 10.0));
  ASSERT_TRUE(own.on_read(1e6, due));
  EXPECT_EQ(due.omega_el_error_rad_s, 0.0);
  EXPECT_EQ(due.omega_el_rad_s, 10.0);
}

}  // namespace
