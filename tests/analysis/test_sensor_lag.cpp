// The winding sensor's τ_s without the network (eq. 14.25, rpem/analysis/thermal/sensor_lag.hpp): runs in which a
// winding moves as no network of ours would, read by r̂s through a lag of its own and by a sensor through τ_s —
// both integrated finely (RK4, 10 ms) rather than with the estimator's step — with seeded noise on each reading.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rpem/analysis/thermal/sensor_lag.hpp"

namespace rpem::analysis {
namespace {

constexpr double kTauR = 2.0, kTauS = 6.0, kDt = 1.0;

/// One run of `steps` of 1 s: the winding's shape of run `i` (a rise, a ripple of its own period, a fall),
/// the two lagged readings from the run's start, each with noise of σ `noise_K`.
SensorLagRun make_run(int i, int steps, double noise_K, std::mt19937& rng) {
  const double rise = 8.0 + 3.0 * i, period = 40.0 + 13.0 * i;
  auto winding = [&](double t) {
    return 40.0 + rise * (1.0 - std::exp(-t / 25.0)) + 1.5 * std::sin(2.0 * M_PI * t / period) -
           (t > 90.0 ? 0.3 * rise * (1.0 - std::exp(-(t - 90.0) / 15.0)) : 0.0);
  };
  std::normal_distribution<double> noise(0.0, noise_K);
  SensorLagRun r;
  double rs = winding(0.0), sensor = winding(0.0);
  constexpr int kSub = 100;
  const double h = kDt / kSub;
  for (int k = 0; k < steps; ++k) {
    if (k > 0) {
      for (int j = 0; j < kSub; ++j) {
        const double t = (k - 1) * kDt + j * h;
        auto rk4 = [&](double y, double tau) {
          auto f = [&](double tt, double yy) { return (winding(tt) - yy) / tau; };
          const double k1 = f(t, y), k2 = f(t + h / 2, y + h / 2 * k1), k3 = f(t + h / 2, y + h / 2 * k2),
                       k4 = f(t + h, y + h * k3);
          return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        };
        rs = rk4(rs, kTauR);
        sensor = rk4(sensor, kTauS);
      }
    }
    r.t_rs_C.push_back(rs + noise(rng));
    r.sensor_C.push_back(sensor + noise(rng));
    r.tau_r_s.push_back(kTauR);
    r.dt_s.push_back(kDt);
  }
  return r;
}

TEST(SensorLagWithoutNetwork, RecoversTheSensorsTimeConstantFromFiveRuns) {
  std::mt19937 rng(11);
  std::vector<SensorLagRun> runs;
  for (int i = 0; i < 5; ++i) runs.push_back(make_run(i, 150, 0.05, rng));
  const SensorLagEstimate e = sensor_lag_without_network(runs, 0.1, 300.0, 20);
  EXPECT_EQ(e.runs, 5u);
  // The discretisation (the input's trapezoid over a 1 s step) and 0.05 K of noise: within 2 % of 6 s (0.4 % seen).
  EXPECT_NEAR(e.tau_s, kTauS, 0.02 * kTauS);
  EXPECT_LT(e.lower_s, kTauS);
  EXPECT_GT(e.upper_s, kTauS);
  EXPECT_GT(e.lower_s, 0.0);  // a lag shown: what the fit asks before it uses it
  // A sensor without a lag is found without one.
  for (SensorLagRun& r : runs) r.sensor_C = r.t_rs_C;  // the sensor reads what r̂s reads: lag_τs(T_rs) = lag_τr(T_rs)
  const SensorLagEstimate same = sensor_lag_without_network(runs, 0.1, 300.0, 20);
  EXPECT_NEAR(same.tau_s, kTauR, 0.02 * kTauR);
  EXPECT_NEAR(same.rs_above_sensor_K, 0.0, 0.01);
}

// A copper law whose reference is a few kelvin off (assumed, or stated roughly) reads every r̂s temperature that
// much above or below the sensor: the offset is fitted with τ_s (eq. 14.25a), not taken as lag. Unfitted, a 3 K
// offset moved the drive cycle's τ_s from 5.5 s to 11.8 s (+3 K) and to 0.1 s (−3 K; docs/thermal.md).
TEST(SensorLagWithoutNetwork, AnOffsetOfTheCopperLawIsFittedBesideTheLagNotTakenForIt) {
  for (const double offset_K : {3.0, -3.0}) {
    std::mt19937 rng(11);
    std::vector<SensorLagRun> runs;
    for (int i = 0; i < 5; ++i) runs.push_back(make_run(i, 150, 0.05, rng));
    for (SensorLagRun& r : runs)
      for (double& t : r.t_rs_C) t += offset_K;
    const SensorLagEstimate e = sensor_lag_without_network(runs, 0.1, 300.0, 20);
    // As without the offset (the same runs, the same noise): within 2 % of 6 s; the offset to 0.05 K (3 σ of
    // the noise's mean over the ≈ 650 judged steps is 0.006 K; the lag's start and discretisation take the rest).
    EXPECT_NEAR(e.tau_s, kTauS, 0.02 * kTauS) << offset_K;
    EXPECT_NEAR(e.rs_above_sensor_K, offset_K, 0.05) << offset_K;
    EXPECT_GT(e.lower_s, 0.0) << offset_K;
    EXPECT_GT(e.upper_s, kTauS) << offset_K;
  }
}

// r̂s's own lag (eq. 14.25b) against the update itself: θ⁺ = θ + a·(θ* − θ) run on a ramp until its lag is
// steady, θ* the ramp at each sample's instant or its mean over the sample's window; the observer reports
// τ_r = Δt/a. Exact for a ramp (the recursion's steady lag is Δt·(1 − a)/a plus the information's age).
/// `steps` of an AR(1) of stationary σ `sigma` and correlation `rho` per step.
std::vector<double> ar1(std::size_t steps, double sigma, double rho, std::mt19937& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> n(steps);
  n[0] = sigma * unit(rng);
  for (std::size_t k = 1; k < steps; ++k) n[k] = rho * n[k - 1] + sigma * std::sqrt(1.0 - rho * rho) * unit(rng);
  return n;
}

TEST(SensorLagWithoutNetwork, CorrelatedNoiseVarianceComesFromSecondDifferences) {
  // On a slow winding (make_run's shapes, periods ≥ 40 s) with AR(1) noise of σ 0.5 K: within 5 % of σ² over 5 000
  // steps (the estimate's own relative σ there is ≈ 3 %), for a noise correlated over 0, 1 and 3 steps.
  for (const double rho : {0.0, std::exp(-1.0), std::exp(-1.0 / 3.0)}) {
    std::mt19937 rng(3);
    std::vector<double> values;
    for (int i = 0; i < 40; ++i) {
      const SensorLagRun r = make_run(i % 5, 125, 1e-9, rng);
      values.insert(values.end(), r.t_rs_C.begin(), r.t_rs_C.end());
    }
    // The runs joined end to end jump between them: judged per run as the fit does.
    const std::vector<double> n = ar1(values.size(), 0.5, rho, rng);
    double sum = 0.0;
    for (std::size_t at = 0; at < values.size(); at += 125) {
      std::vector<double> run(values.begin() + static_cast<std::ptrdiff_t>(at),
                              values.begin() + static_cast<std::ptrdiff_t>(at + 125));
      for (std::size_t k = 0; k < run.size(); ++k) run[k] += n[at + k];
      sum += correlated_noise_variance(run, rho);
    }
    EXPECT_NEAR(sum / 40.0, 0.25, 0.05 * 0.25) << rho;
  }
  EXPECT_EQ(correlated_noise_variance({1.0, 2.0}, 0.5), 0.0);
}

// r̂s's own noise is correlated over its time constant (the update's AR(1)); lagged by τ_s it shrinks as τ_s grows,
// so the plain least squares takes a longer τ_s than the sensor's (eq. 14.25c). With the noise's correlation time
// given, its variance comes from each run's second differences and its expected share is taken out.
TEST(SensorLagWithoutNetwork, RsOwnCorrelatedNoiseIsTakenOutNotTakenForLag) {
  constexpr double kSigma = 1.0;  // K: r̂s's stationary correlated noise
  constexpr int kSeeds = 10;      // the mean over ten logs of eight runs: one log's spread is ±5 %
  double plain_sum = 0.0, compensated_sum = 0.0;
  int held = 0;
  for (int seed = 20; seed < 20 + kSeeds; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::vector<SensorLagRun> runs;
    for (int i = 0; i < 8; ++i) {
      SensorLagRun r = make_run(i, 150, 0.05, rng);  // 0.05 K white on both; r̂s's correlated noise on top
      const std::vector<double> n = ar1(r.t_rs_C.size(), kSigma, std::exp(-kDt / kTauR), rng);
      for (std::size_t k = 0; k < n.size(); ++k) r.t_rs_C[k] += n[k];
      runs.push_back(r);
    }
    plain_sum += sensor_lag_without_network(runs, 0.1, 300.0, 20).tau_s;
    for (SensorLagRun& r : runs) r.rs_noise_tau_s.assign(r.t_rs_C.size(), kTauR);
    const SensorLagEstimate e = sensor_lag_without_network(runs, 0.1, 300.0, 20);
    compensated_sum += e.tau_s;
    if (e.lower_s < kTauS && kTauS < e.upper_s) ++held;
    runs.front().rs_noise_tau_s.pop_back();  // a correlation time missing on a step: not a run
    EXPECT_EQ(sensor_lag_without_network(runs, 0.1, 300.0, 20).runs, runs.size() - 1);
  }
  // Seen: the plain mean 6.51 s (+8.5 %), compensated 6.09 s (+1.5 %), 9 of the 10 intervals holding 6 s.
  EXPECT_GT(plain_sum / kSeeds, 1.05 * kTauS);                 // the bias this removes, seen
  EXPECT_NEAR(compensated_sum / kSeeds, kTauS, 0.03 * kTauS);  // removed
  EXPECT_GE(held, 8);
}

TEST(SensorLagWithoutNetwork, TheEstimatorsLagBehindARampIsItsTimeConstantLessTheAgeOfItsInformation) {
  constexpr double kRate = 0.3;  // K/s
  for (const double dt : {0.1, 0.5, 2.0})
    for (const double a : {0.05, 0.22, 0.6})
      for (const bool window_means : {false, true}) {
        double theta = 0.0, t = 0.0;
        for (int k = 0; k < 2000; ++k) {
          t += dt;
          const double target = kRate * (window_means ? t - 0.5 * dt : t);
          theta += a * (target - theta);
        }
        const double lag_s = t - theta / kRate;
        EXPECT_NEAR(estimator_ramp_lag_s(dt / a, dt, window_means), lag_s, 1e-9 * (1.0 + lag_s))
            << "dt " << dt << " a " << a << (window_means ? " window means" : " instants");
      }
  EXPECT_EQ(estimator_ramp_lag_s(0.5, 1.0, false), 0.0);  // a > 1 would lead the ramp: no lag, not a negative one
}

TEST(SensorLagWithoutNetwork, FewRunsGiveNoIntervalAndNoneGiveNoEstimate) {
  std::mt19937 rng(5);
  std::vector<SensorLagRun> runs{make_run(0, 150, 0.05, rng), make_run(1, 150, 0.05, rng)};
  const SensorLagEstimate two = sensor_lag_without_network(runs, 0.1, 300.0, 20);
  EXPECT_NEAR(two.tau_s, kTauS, 0.1 * kTauS);
  EXPECT_TRUE(std::isinf(two.lower_s) && std::isinf(two.upper_s));
  EXPECT_TRUE(std::isnan(sensor_lag_without_network({}, 0.1, 300.0, 20).tau_s));
  runs.resize(1);
  runs[0].dt_s.pop_back();  // inconsistent lengths: not a run
  EXPECT_TRUE(std::isnan(sensor_lag_without_network(runs, 0.1, 300.0, 20).tau_s));
}

}  // namespace
}  // namespace rpem::analysis
