// q_c of an unread coolant from a log's coolant readings (analysis/thermal/coolant_drift.hpp, docs/derivations.md
// eq. 14.29b), on coolant series drawn here: a random walk seen through the readings' noise, a coolant that only
// the readings' noise and resolution move, a coolant controlled about its set point (a bounded move), two sessions
// whose steps are not one another's lags, and a log without coolant readings.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "rpem/analysis/thermal/coolant_drift.hpp"

namespace rpem::analysis {
namespace {

/// One session of `coolant_C` per 1 s step, each step read.
template <class Coolant>
ThermalRecord record_of(std::size_t steps, Coolant coolant_C) {
  ThermalRecord r;
  r.coolant = true;
  for (std::size_t k = 0; k < steps; ++k) {
    core::ThermalStepData s;
    s.load.dt_s = 1.0;
    s.load.coolant_C = coolant_C(k);
    s.coolant_read = true;
    r.steps.push_back(s);
    r.t_s.push_back(static_cast<double>(k + 1));
  }
  return r;
}

TEST(CoolantDrift, AWalkSeenThroughNoisyReadingsGivesItsIntensity) {
  // q = 10⁻³ K²/s under readings with a σ of 0.05 K (2σ² = 0.005 K², five seconds of the walk). Each lag's D is a
  // mean over at least 32 independent moves, and eq. 14.29b counts a move only beyond two of its standard errors
  // (2·√(2·lag/pairs) of D, 11 % at 16 steps) and the floor (one step's move, 1/16 at 16 steps): from below, q_c
  // reads about 0.8·q where those two are smallest against the move; from above, chance in the maximum over ten
  // lags. Measured on these four seeds: 0.78–0.92·q.
  constexpr double kQ = 1e-3;
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> step(0.0, std::sqrt(kQ)), noise(0.0, 0.05);
    double walk = 30.0;
    const ThermalRecord r = record_of(20000, [&](std::size_t) { return (walk += step(rng)) + noise(rng); });
    const CoolantDrift d = coolant_drift(r, r.steps.size());
    EXPECT_GE(d.lags, 8);
    EXPECT_GT(d.q_K2_per_s, 0.7 * kQ) << "seed " << seed;
    EXPECT_LT(d.q_K2_per_s, 1.25 * kQ) << "seed " << seed;
    EXPECT_NEAR(d.floor_K2, 2.0 * 0.05 * 0.05 + kQ, 0.5 * (2.0 * 0.05 * 0.05 + kQ));
  }
}

TEST(CoolantDrift, ReadingsOnlyTheirNoiseMovesGiveNoWalk) {
  // A coolant at 25 °C read with a σ of 0.1 K at 0.1 K resolution: every lag's D is 2σ² but for its sampling
  // error. What q_c makes of that sampling error over ten minutes stays below the readings' own variance.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1);
  const ThermalRecord r = record_of(20000, [&](std::size_t) { return std::round((25.0 + noise(rng)) * 10.0) / 10.0; });
  const CoolantDrift d = coolant_drift(r, r.steps.size());
  EXPECT_LT(d.q_K2_per_s * 600.0, 0.1 * 0.1);
}

TEST(CoolantDrift, AControlledCoolantIsBoundedAtEveryLag) {
  // A coolant loop holding 40 °C: a swing of ±1.5 K with a 20 min period. D(s) = 2·1.5²·sin²(π·s/1200 s) levels off;
  // q_c·s bounds it at every lag measured but for the two standard errors the estimate allows D there (a relative
  // 2·√(2·lag/pairs), the moves taken as Gaussian, 1 % for the finite series besides), and q_c is set where the swing
  // is steepest against the lag, not at 1 s.
  constexpr std::size_t kSteps = 40000;
  const ThermalRecord r = record_of(
      kSteps, [](std::size_t k) { return 40.0 + 1.5 * std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / 1200.0); });
  const CoolantDrift d = coolant_drift(r, r.steps.size());
  for (std::size_t lag = 1; static_cast<double>(lag) <= d.longest_lag_s; lag *= 2) {
    const double s = static_cast<double>(lag);
    const double move = 2.0 * 1.5 * 1.5 * std::pow(std::sin(std::numbers::pi * s / 1200.0), 2);
    const double allowed = 2.0 * move * std::sqrt(2.0 * s / static_cast<double>(kSteps - lag)) + 0.01 * move;
    EXPECT_GE(d.q_K2_per_s * s, move - d.floor_K2 - allowed) << s << " s";
  }
  EXPECT_GT(d.at_lag_s, 100.0);
}

TEST(CoolantDrift, SessionsAreMeasuredEachOnItsOwnAndUnreadStepsAreLeftOut) {
  // Two sessions 50 K apart: the jump between them is no move of the coolant. Every third step unread (its held
  // value would read as no move).
  std::mt19937_64 rng(11);
  std::normal_distribution<double> step(0.0, std::sqrt(1e-3));
  double walk = 20.0;
  ThermalRecord r = record_of(8000, [&](std::size_t k) { return (walk += step(rng)) + (k >= 4000 ? 50.0 : 0.0); });
  r.session_first_step = {0, 4000};
  r.session_coolant = {true, true};
  for (std::size_t k = 0; k < r.steps.size(); k += 3) r.steps[k].coolant_read = false;
  const CoolantDrift d = coolant_drift(r, r.steps.size());
  EXPECT_GT(d.q_K2_per_s, 0.5e-3);
  EXPECT_LT(d.q_K2_per_s, 2e-3);
}

TEST(CoolantDrift, NoCoolantReadingsGiveZeroAndSaySo) {
  ThermalRecord r = record_of(5000, [](std::size_t) { return 25.0; });
  for (core::ThermalStepData& s : r.steps) s.coolant_read = false;
  const CoolantDrift d = coolant_drift(r, r.steps.size());
  EXPECT_EQ(d.q_K2_per_s, 0.0);
  EXPECT_EQ(d.lags, 0);
  EXPECT_NE(coolant_drift_sentence(d).find("no coolant readings"), std::string::npos);
  // Too short a training part to measure two lags: 0, said the same way.
  const ThermalRecord short_log = record_of(40, [](std::size_t k) { return 25.0 + 0.1 * static_cast<double>(k); });
  EXPECT_EQ(coolant_drift(short_log, short_log.steps.size()).q_K2_per_s, 0.0);
}

}  // namespace
}  // namespace rpem::analysis
