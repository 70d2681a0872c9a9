// core::window_mean_speed_rad_s against a type-2 PLL run as VESC's firmware runs it (support/pll_reads.hpp) on a
// rotor whose speed profile is known, read every h: each window's rebuilt mean speed against the rotor's true mean
// over the window, with the derived error bounds.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

#include "rpem/core/frames.hpp"
#include "rpem/core/reported_speed.hpp"
#include "support/pll_reads.hpp"

namespace {

using rpem::core::AveragedSample;
using rpem::core::CountRead;
using rpem::core::grown_count_speed_rad_s;
using rpem::core::kCountRunSideMaxS;
using rpem::core::SpeedRead;
using rpem::core::window_mean_speed_rad_s;
using rpem::core::window_speed_rad_s;

using rpem::test::kPllKi;
using rpem::test::kPllKp;
using Window = rpem::test::PllWindow;
constexpr double kKp = kPllKp, kKi = kPllKi;
constexpr double kDt = rpem::test::kPllCycleS;

using rpem::test::run_pll;

// A steady ramp: the PLL's speed lags it by k_p/k_i, so the speed at the read is off the window's mean by
// a·(h/2 − k_p/k_i); rebuilt, the mean is exact to the loop's discretisation (measured: the discrete PLL lags
// by 1.5 cycles more, as it turns its angle with the speed before this cycle's update: 1.5·a·dt).
TEST(ReportedSpeed, ARampsWindowMeanIsRebuiltExactlyWhereTheReadIsOffByTheLag) {
  constexpr double a = 500.0;                 // rad/s² electrical
  for (const int read_cycles : {1125, 62}) {  // 90 ms (VESC Tool at 11 Hz) and ~5 ms (rpemd at 200 Hz)
    const std::vector<Window> w = run_pll([](double t) { return 100.0 + a * t; }, 3.0, read_cycles);
    const double h = read_cycles * kDt;
    for (const Window& x : w) {
      if (x.t_s < 1.0) continue;  // the PLL's start-up: e^{−15 t} below 1e-6 of the lag
      EXPECT_NEAR(x.at_read - x.true_mean, a * (0.5 * h - kKp / kKi), 0.02 * a * kKp / kKi) << "h " << h;
      EXPECT_NEAR(x.rebuilt, x.true_mean, 2.0 * a * kDt) << "h " << h << " at " << x.t_s;
    }
  }
}

// Where the acceleration changes (a ramp that starts or stops), the PLL's speed bends with its slow pole
// (15.1/s): |ω̂''| ≤ a·p₁p₂/(p₂ − p₁) = a·k_i/√(k_p² − 4k_i), so the trapezoid of the two reads misses the
// mean of ω̂ by at most h²/12 of that, and the dropped term (1/k_i)·Δω̂'/h is at most a/(k_i·h) and at most
// max|ω̂''|/k_i = a/√(k_p² − 4k_i).
TEST(ReportedSpeed, WhereTheAccelerationChangesTheErrorIsWithinTheTrapezoidsBound) {
  constexpr double a = 2000.0;  // a hard acceleration: 0 to 2000 rad/s in 1 s, then steady
  for (const int read_cycles : {1125, 62}) {
    const std::vector<Window> w =
        run_pll([](double t) { return t < 0.5 ? 50.0 : 50.0 + a * std::min(t - 0.5, 1.0); }, 3.0, read_cycles);
    const double h = read_cycles * kDt;
    const double root = std::sqrt(kKp * kKp - 4.0 * kKi);
    const double bound = h * h / 12.0 * a * kKi / root + std::min(a / (kKi * h), a / root) + 2.0 * a * kDt;
    double worst = 0.0, worst_at_read = 0.0;
    for (const Window& x : w) {
      worst = std::max(worst, std::abs(x.rebuilt - x.true_mean));
      worst_at_read = std::max(worst_at_read, std::abs(x.at_read - x.true_mean));
    }
    std::printf("[ speed    ] h %.4f s: rebuilt within %.3f rad/s (bound %.3f), as read %.1f rad/s\n", h, worst, bound,
                worst_at_read);
    EXPECT_LE(worst, bound) << "h " << h;
    // As reported it is off by up to the lag's a·(τ − h/2) (minus the PLL's own catching up at the ends).
    EXPECT_GT(worst_at_read, 0.5 * a * (kKp / kKi - 0.5 * h)) << "h " << h;
    EXPECT_LT(worst, 0.2 * worst_at_read) << "h " << h;
  }
}

/// The error the reads show for window k of `w` (core::window_mean_speed_error_rad_s): the larger change of the
/// PLL's mean acceleration at the window's two ends, as the log's reader takes it (io/src/averaged_log.cpp).
double error_the_reads_show(const std::vector<Window>& w, std::size_t k, double h) {
  const auto read = [&](std::size_t j) { return SpeedRead{std::llround(w[j].t_s * 1e9), w[j].at_read}; };
  const rpem::core::PllGains pll{kKp, kKi};
  double change = 0.0;
  if (k >= 2) change = std::abs(rpem::core::read_accel_change_rad_s2(read(k - 2), read(k - 1), read(k)));
  if (k >= 1 && k + 1 < w.size())
    change = std::max(change, std::abs(rpem::core::read_accel_change_rad_s2(read(k - 1), read(k), read(k + 1))));
  return rpem::core::window_mean_speed_error_rad_s(pll, change, h);
}

// docs/derivations.md §13, "… where the acceleration changes": where the rotor's acceleration changes (a stop at a
// constant braking current, one through zero into a reversal, a ramp's start, a step of acceleration), the rebuilt
// mean is off by about h²/12·|Δa|·g_max + |Δâ|/(k_i·h), which the reads show through the change Δâ of the PLL's mean
// acceleration. Measured against the PLL run per cycle: within E (and the loop's 1.5-cycle lag) wherever the reads
// lie 5 ms, 240 ms or 1 s apart; at 56 and 90 ms the window where a stop begins is off by up to 1/0.71 of its E (4–6
// rad/s beyond it: the change reaches the PLL's speed over its 66 ms pole, after the reads that bound the window) — E
// still far above any read's noise there. Where the acceleration holds, E is nothing.
TEST(ReportedSpeed, TheErrorTheReadsShowCoversTheRebuildWhereTheAccelerationChanges) {
  constexpr double a = 11000.0;  // rad/s² electrical: seed 1's stop (tests/independent_vesc), 3 400 rad/s in 0.31 s
  const std::vector<std::pair<const char*, std::function<double(double)>>> profiles{
      {"stop", [](double t) { return t < 0.5 ? 3400.0 : std::max(0.0, 3400.0 - a * (t - 0.5)); }},
      {"stop through zero", [](double t) { return 3400.0 - a * std::clamp(t - 0.5, 0.0, 0.4); }},
      {"ramp's start", [](double t) { return 50.0 + 2000.0 * std::clamp(t - 0.5, 0.0, 1.0); }},
      {"acceleration step", [](double t) { return 100.0 + (t > 0.5 ? 5000.0 * (t - 0.5) : 0.0); }}};
  for (const auto& [name, omega] : profiles) {
    for (const int read_cycles : {62, 700, 1125, 3000, 12500}) {  // 5 ms … 1 s
      const double h = read_cycles * kDt;
      const std::vector<Window> w = run_pll(omega, 4.5, read_cycles);
      double worst_beyond = 0.0, least_ratio = 1e300;
      for (std::size_t k = 1; k < w.size(); ++k) {  // the first window starts at the PLL's start, before any read
        if (w[k].t_s < 0.3) continue;               // the PLL's start-up
        const double error = std::abs(w[k].rebuilt - w[k].true_mean);
        const double e = error_the_reads_show(w, k, h);
        worst_beyond = std::max(worst_beyond, error - e - 1.5 * a * kDt);
        if (error > 20.0 * a * kDt) least_ratio = std::min(least_ratio, e / error);
      }
      std::printf("[ speed    ] %s, h %.4f s: beyond E by %.2f rad/s at most; E/error ≥ %.2f (errors above %.1f rad/s)\n",
                  name, h, worst_beyond, least_ratio < 1e300 ? least_ratio : std::nan(""), 20.0 * a * kDt);
      const bool between = read_cycles == 700 || read_cycles == 1125;  // 56 and 90 ms
      if (!between) {
        EXPECT_LE(worst_beyond, 0.0) << name << ", h " << h;
      }
      if (least_ratio < 1e300) {
        EXPECT_GE(least_ratio, between ? 0.6 : 0.9) << name << ", h " << h;
      }
    }
  }
  // A steady ramp after its start: no change of acceleration, no error, E nothing (the loop's discretisation only).
  const std::vector<Window> ramp = run_pll([](double t) { return 100.0 + 500.0 * t; }, 3.0, 1125);
  for (std::size_t k = 0; k < ramp.size(); ++k) {
    if (ramp[k].t_s > 1.0) {
      EXPECT_LT(error_the_reads_show(ramp, k, 1125 * kDt), 1e-3) << ramp[k].t_s;
    }
  }
}

// The PLL's impulse response's peak: 14.56 /s at 2.48 ms for VESC's defaults (overdamped), below the
// k_i/√(k_p² − 4k_i) = 15.23 /s of the bound above; critically damped k_i/(e·k_p/2); underdamped at most √k_i. With
// the gains not given (the speed is the window's own mean) there is no rebuild and no error.
TEST(ReportedSpeed, TheErrorsCoefficientIsThePllsImpulsePeak) {
  const auto per_change = [](double kp, double ki, double h) {
    return rpem::core::window_mean_speed_error_rad_s({kp, ki}, 1.0, h);
  };
  // Overdamped: the peak written out from the two poles, h²/12·g + 1/(k_i·h) at h = 0.1 s.
  const double root = std::sqrt(kKp * kKp - 4.0 * kKi), p1 = 0.5 * (kKp - root), p2 = 0.5 * (kKp + root);
  const double t_peak = std::log(p2 / p1) / (p2 - p1);
  const double g = kKi * (std::exp(-p1 * t_peak) - std::exp(-p2 * t_peak)) / (p2 - p1);
  EXPECT_NEAR(g, 14.559, 1e-3);
  EXPECT_NEAR(t_peak, 2.476e-3, 1e-6);
  EXPECT_NEAR(per_change(kKp, kKi, 0.1), 0.01 / 12.0 * g + 1.0 / (kKi * 0.1), 1e-15);
  // Critically damped (k_p² = 4k_i = 4·10⁴): g = k_i·t·e^{−t·k_p/2}, its peak at t = 2/k_p.
  EXPECT_NEAR(per_change(200.0, 1e4, 0.1), 0.01 / 12.0 * 1e4 * (2.0 / 200.0) * std::exp(-1.0) + 1.0 / (1e4 * 0.1), 1e-12);
  // Underdamped: at most ω_n = √k_i.
  EXPECT_NEAR(per_change(50.0, 1e4, 0.1), 0.01 / 12.0 * 100.0 + 1.0 / (1e4 * 0.1), 1e-12);
  EXPECT_EQ(rpem::core::window_mean_speed_error_rad_s({}, 1e4, 0.1), 0.0);
  EXPECT_EQ(rpem::core::window_mean_speed_error_rad_s({kKp, kKi}, 1e4, 0.0), 0.0);
  // The change of the mean acceleration over three reads; reads at one instant show none.
  EXPECT_NEAR(rpem::core::read_accel_change_rad_s2({0, 0.0}, {100'000'000, 10.0}, {300'000'000, 50.0}), 200.0 - 100.0, 1e-9);
  EXPECT_EQ(rpem::core::read_accel_change_rad_s2({0, 0.0}, {0, 10.0}, {300'000'000, 50.0}), 0.0);
}

// The noise of the changes of acceleration around a window: σ = 1.4826·median|Δâ| of a run, the lower middle one of
// an even count, NaNs (changes over an unknown window) left out, none from fewer than three; robust to the few that
// are the rotor's own.
TEST(ReportedSpeed, TheChangesNoiseIsTheirMediansOverARun) {
  constexpr double kPerMedian = 1.4826022185056018;
  std::array<double, 5> odd{-3.0, 1.0, 200.0, -2.0, 5.0};  // |·| sorted: 1 2 3 5 200
  EXPECT_DOUBLE_EQ(rpem::core::accel_change_sigma_rad_s2(odd), kPerMedian * 3.0);
  std::array<double, 6> even{-3.0, 1.0, std::nan(""), 4.0, -2.0, 9.0};  // 1 2 3 4 9: NaN out
  EXPECT_DOUBLE_EQ(rpem::core::accel_change_sigma_rad_s2(even), kPerMedian * 3.0);
  std::array<double, 4> two{1.0, std::nan(""), -7.0, std::nan("")};
  EXPECT_EQ(rpem::core::accel_change_sigma_rad_s2(two), 0.0);
  // A run of jitter with two changes of a stop (thousands) among them: the stop moves σ by one rank, not to its size.
  std::array<double, rpem::core::kAccelChangeRunReads> run{12.0,  -61.0, 35.0, -8.0, 77.0,  -41.0, 20.0,  55.0, -95.0,
                                                           -27.0, 3.0,   9e3,  6e3,  -33.0, 48.0,  -70.0, 15.0};
  EXPECT_DOUBLE_EQ(rpem::core::accel_change_sigma_rad_s2(run), kPerMedian * 41.0);  // without the stop's two: 35
}

// A constant speed is its own mean, however the reads fall; reads at one instant give the reported speed,
// and a window starting after the previous read (another reader reset the means there) takes the PLL's
// speed interpolated at its start.
TEST(ReportedSpeed, ConstantSpeedAndDegenerateReads) {
  EXPECT_DOUBLE_EQ(window_mean_speed_rad_s({0, 700.0}, {90'000'000, 700.0}, 0, 0.0667), 700.0);
  EXPECT_DOUBLE_EQ(window_mean_speed_rad_s({5, 100.0}, {5, 700.0}, 5, 0.0667), 700.0);
  // ω̂ from 100 to 200 over 100 ms: slope 1000/s; the window [50 ms, 100 ms] has trapezoid 175 and lag 66.7 ms.
  EXPECT_NEAR(window_mean_speed_rad_s({0, 100.0}, {100'000'000, 200.0}, 50'000'000, 0.0667), 175.0 + 66.7, 1e-9);
}

// A rocking stall's reads: the window's mean can be near zero while the reads show the speeds it passed through
// (docs/derivations.md §13, "A stall's rocking"). The larger magnitude of the two, either sign; a missing read (NaN)
// leaves the other.
TEST(ReportedSpeed, TheReadsSpeedMaximumIsTheLargerMagnitudeOfTheTwoReads) {
  using rpem::core::reads_speed_max_rad_s;
  EXPECT_DOUBLE_EQ(reads_speed_max_rad_s({0, -4.0}, {90'000'000, -142.0}), 142.0);
  EXPECT_DOUBLE_EQ(reads_speed_max_rad_s({0, 153.0}, {90'000'000, -102.0}), 153.0);
  EXPECT_DOUBLE_EQ(reads_speed_max_rad_s({0, std::nan("")}, {90'000'000, -102.0}), 102.0);
  // A window whose rebuilt mean is zero (VESC's lag k_p/k_i = 66.7 ms leads a 90 ms window's trapezoid by 21.7 ms:
  // mean = ω̂₂ + (ω̂₂ − ω̂₁)·0.2407) while its reads show −103 rad/s: the frame's error acts at the reads' speed.
  const double mean = window_mean_speed_rad_s({0, -103.08}, {90'000'000, -20.0}, 0, kKp / kKi);
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_DOUBLE_EQ(reads_speed_max_rad_s({0, -103.08}, {90'000'000, -20.0}), 103.08);
}

// A count of the angle's steps: the run's mean speed is travel over time; the window's speed is the count's only
// below the staircase speed (strictly), and the reported one without a count, above it, or with no staircase.
TEST(ReportedSpeed, TheCountsSpeedReplacesTheReportedOneOnlyBelowTheStaircaseSpeed) {
  AveragedSample a;
  a.omega_el_rad_s = 2.0;
  EXPECT_DOUBLE_EQ(window_speed_rad_s(a, 52.36), 2.0);  // no count
  a.omega_counted_el_rad_s = -7.5;
  EXPECT_DOUBLE_EQ(window_speed_rad_s(a, 52.36), -7.5);
  EXPECT_DOUBLE_EQ(window_speed_rad_s(a, 7.5), 2.0);  // at the staircase speed: reported
  EXPECT_DOUBLE_EQ(window_speed_rad_s(a, 0.0), 2.0);  // no staircase (not angle_source: hall)
}

// Reads of a count of 60° steps (floor of the rotor's angle over a step) every `period_s` (jittered ±20 %) of
// a rotor at angle θ(t); the count's speed of the window ending at the read nearest `at_s`, and that window's
// true mean speed (travel over its time, exactly).
struct CountedWindow {
  double counted_rad_s = 0.0, true_rad_s = 0.0, run_s = 0.0;
};
CountedWindow count_window(const std::function<double(double)>& theta, double period_s, double duration_s, double at_s) {
  constexpr double kStep = std::numbers::pi / 3.0;
  std::vector<CountRead> reads;
  std::uint32_t lcg = 12345;
  for (double t = 0.0; t < duration_s;) {
    reads.push_back({static_cast<std::int64_t>(std::llround(t * 1e9)), kStep * std::floor(theta(t) / kStep)});
    lcg = lcg * 1664525u + 1013904223u;
    t += period_s * (0.8 + 0.4 * (lcg >> 8) / 16777216.0);
  }
  std::size_t e = 1;
  while (e + 1 < reads.size() && rpem::core::to_seconds(reads[e].t_ns) < at_s) ++e;
  CountedWindow w;
  w.counted_rad_s = grown_count_speed_rad_s(reads, e - 1, e, kStep, static_cast<std::int64_t>(kCountRunSideMaxS * 1e9));
  const double t0 = rpem::core::to_seconds(reads[e - 1].t_ns), t1 = rpem::core::to_seconds(reads[e].t_ns);
  w.true_rad_s = (theta(t1) - theta(t0)) / (t1 - t0);
  return w;
}

// At a constant speed the run grows to its horizon on both sides (the sides agree within their resolution), so
// a 5 ms window at a crawl is counted over ≈ 0.5 s: within one step over the run (2.1 rad/s) of its speed, where
// the window's own count (0 or 1 step in 5 ms) is off by up to 209 rad/s. Under a constant acceleration the
// centred run's mean is the window's (a symmetric run in reads, jittered: within the step bound and the
// acceleration times the centres' offset, ≤ a·20 % of a read).
TEST(ReportedSpeed, AWindowsCountGrowsOverAConstantSpeedToItsHorizon) {
  constexpr double kStep = std::numbers::pi / 3.0;
  for (const double w : {3.0, 20.0, -40.0}) {
    const CountedWindow c = count_window([w](double t) { return 0.7 + w * t; }, 0.005, 3.0, 1.5);
    EXPECT_NEAR(c.counted_rad_s, c.true_rad_s, kStep / (2.0 * kCountRunSideMaxS - 0.02)) << w;
  }
  const double a = 40.0;  // rad/s², 10 → 70 rad/s over 1.5 s
  const CountedWindow c = count_window([a](double t) { return 10.0 * t + 0.5 * a * t * t; }, 0.005, 2.0, 1.0);
  EXPECT_NEAR(c.counted_rad_s, c.true_rad_s, kStep / (2.0 * kCountRunSideMaxS - 0.02) + a * 0.002);
}

// A rotor that stops: 40 rad/s until 1 s, then standing. 100 ms after the stop the side reaching back into the
// motion counts ≈ 4 steps where the other counts none, so the run stops growing before it: the window's counted
// speed is near 0 (within the step over the shortest run, 3 reads ≈ 15 ms, i.e. 70 rad/s at worst; here it is
// within 2·step over the 0.2 s run the sides allowed), not the ≈ 12 rad/s of a run over the horizon.
TEST(ReportedSpeed, AWindowsCountStopsGrowingWhereItsSidesDisagree) {
  const auto theta = [](double t) { return 40.0 * std::min(t, 1.0); };
  const CountedWindow c = count_window(theta, 0.005, 2.0, 1.1);
  EXPECT_DOUBLE_EQ(c.true_rad_s, 0.0);
  EXPECT_LT(std::abs(c.counted_rad_s), 2.0 * (std::numbers::pi / 3.0) / 0.19) << c.counted_rad_s;
}

// Degenerate runs: no window (s ≥ e), reads at one instant.
TEST(ReportedSpeed, ACountWithoutARunIsNotANumber) {
  const std::vector<CountRead> reads{{0, 0.0}, {0, 1.0}, {10, 2.0}};
  EXPECT_TRUE(std::isnan(grown_count_speed_rad_s(reads, 1, 1, 1.0, 1'000'000)));
  EXPECT_TRUE(std::isnan(grown_count_speed_rad_s(reads, 2, 1, 1.0, 1'000'000)));
  const std::vector<CountRead> same{{5, 0.0}, {5, 1.0}};
  EXPECT_TRUE(std::isnan(grown_count_speed_rad_s(same, 0, 1, 1.0, 1'000'000)));
  EXPECT_DOUBLE_EQ(grown_count_speed_rad_s(reads, 1, 2, 1.0, 1'000'000), 2.0 / 10e-9);  // m = 1: reads 0 to 2
}

}  // namespace
