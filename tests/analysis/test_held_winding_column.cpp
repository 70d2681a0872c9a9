// A winding-sensor column that holds one value while r̂s says the winding moved (docs/derivations.md eq. 14.28b):
// `rpem thermal fit` sets those readings aside before it fits a network to them. Records built here step by step:
// a first-order winding (τ 600 s, 25 → 85 °C), r̂s reading it through copper's law with Gaussian noise of a stated σ,
// and the sensor's column live, lagging, quantised or held. And the fit's second look (eq. 14.28c), where r̂s never
// adapts: the filter with a fitted network (here the machine's own) refuses the held value, and its run goes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "rpem/analysis/normal_quantile.hpp"
#include "rpem/analysis/thermal/held_winding_column.hpp"
#include "support/paper_thermal.hpp"

namespace rpem::analysis {
namespace {

constexpr core::DriftLaw kCopperLaw{core::kCopper.typical_per_K, 20.0, 0.05};
constexpr double kRho = core::kCopper.typical_per_K / core::kCopper.max_per_K;  // eq. 14.28b's ρ: 1/1.15
constexpr double kSensorSigma_K = 1.0;

/// The winding's truth per 1 s step: from 25 °C towards 85 °C with τ 600 s.
std::vector<double> heat_up(std::size_t steps) {
  std::vector<double> w(steps);
  for (std::size_t k = 0; k < steps; ++k) w[k] = 85.0 - 60.0 * std::exp(-static_cast<double>(k + 1) / 600.0);
  return w;
}

/// A reading of resolution q (0: exact) of the winding through a first-order lag τ_s (0: none).
std::vector<double> live_sensor(const std::vector<double>& winding_C, double q, double tau_s) {
  std::vector<double> out(winding_C.size());
  double lagged = winding_C.front();
  for (std::size_t k = 0; k < winding_C.size(); ++k) {
    lagged = tau_s > 0.0 ? winding_C[k] + (lagged - winding_C[k]) * std::exp(-1.0 / tau_s) : winding_C[k];
    out[k] = q > 0.0 ? q * std::round(lagged / q) : lagged;
  }
  return out;
}

/// A record of 1 s steps: r̂s adapting on every step (unless `rs_adapts` is false) with noise σ_rs.
ThermalRecord record_of(const std::vector<double>& winding_C, const std::vector<double>& reading_C, double sigma_rs_K,
                        unsigned seed, bool rs_adapts = true) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_rs_K);
  const double ohm_per_K = kCopperLaw.value_ref * kCopperLaw.coeff_per_K;
  ThermalRecord r;
  r.log = "ride.csv";
  r.session_logs = {r.log};
  r.winding_sensor = true;
  for (std::size_t k = 0; k < winding_C.size(); ++k) {
    core::ThermalStepData s;
    s.load.dt_s = 1.0;
    s.winding_sensor_C = reading_C[k];
    core::ParameterObservation& p = s.parameter[core::kRs];
    p.valid = rs_adapts;
    p.value = kCopperLaw.at(winding_C[k] + noise(rng));
    p.variance = std::pow(sigma_rs_K * ohm_per_K, 2);
    r.steps.push_back(s);
    r.t_s.push_back(static_cast<double>(k + 1));
  }
  return r;
}

std::size_t readings(const ThermalRecord& r) {
  std::size_t n = 0;
  for (const core::ThermalStepData& s : r.steps) n += std::isfinite(s.winding_sensor_C) ? 1 : 0;
  return n;
}

// Reference values from the normal table (Abramowitz & Stegun 26.2): Φ(−z) = 2.5 %, 0.05 %, 5·10⁻⁷.
TEST(NormalQuantile, MatchesTheTable) {
  EXPECT_NEAR(upper_normal_quantile(0.025), 1.959964, 1e-6);
  EXPECT_NEAR(upper_normal_quantile(0.0005), 3.290527, 1e-6);
  EXPECT_NEAR(upper_normal_quantile(5e-7), 4.891638, 1e-6);
}

// A disabled input's 0 °C on every step of a heat-up: r̂s sees the winding rise ~57 K; the whole column goes, and the
// record is left without a winding sensor. The largest move (14.28b) finds is ρ·(the winding's rise to the last step
// ± the two ends' noise): 0.87·(85 − 25.1 − 60·e⁻³) = 49.8 K, within 5σ·√2 = 7.1 K.
TEST(HeldWindingColumn, AValueOnEveryStepIsNoSensor) {
  const std::vector<double> w = heat_up(1800);
  ThermalRecord r = record_of(w, std::vector<double>(w.size(), 0.0), 1.0, 1);
  const HeldWindingColumn held = drop_held_winding_readings(r, kCopperLaw, kSensorSigma_K, 0.0);
  ASSERT_EQ(held.runs.size(), 1U);
  EXPECT_TRUE(held.runs[0].whole_session);
  EXPECT_EQ(held.runs[0].first, 0U);
  EXPECT_EQ(held.runs[0].end, w.size());
  EXPECT_NEAR(held.runs[0].moved_K, kRho * (w.back() - w.front()), 7.1);
  EXPECT_DOUBLE_EQ(held.resolution_K, kCoarsestReadingResolution_K);  // it never moves: the coarsest a drive gives
  // z at 2·M·Φ(−z) = 10⁻³ with M = 1799 comparisons: Φ(−z) = 2.78·10⁻⁷.
  EXPECT_NEAR(held.z, upper_normal_quantile(kHeldColumnFalseRate / (2.0 * 1799.0)), 1e-12);
  EXPECT_EQ(readings(r), 0U);
  EXPECT_FALSE(r.winding_sensor);
  const std::vector<std::string> said = held.describe("T_winding");
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("T_winding holds 0 °C on every step of ride.csv (1800 steps)"), std::string::npos) << said[0];
}

// A 0.1 K sensor stuck 10 min into the heat-up: its readings from the step its last value came go, those before stay.
// At 10 min the winding rises 0.037 K/s, so the stuck value came at most 3 steps before (0.1 K / 0.037 K/s).
TEST(HeldWindingColumn, AStuckSensorLosesItsHeldReadingsOnly) {
  const std::vector<double> w = heat_up(1800);
  std::vector<double> y = live_sensor(w, 0.1, 0.0);
  for (std::size_t k = 600; k < y.size(); ++k) y[k] = y[599];
  ThermalRecord r = record_of(w, y, 1.0, 2);
  const HeldWindingColumn held = drop_held_winding_readings(r, kCopperLaw, kSensorSigma_K, 0.0);
  ASSERT_EQ(held.runs.size(), 1U);
  EXPECT_FALSE(held.runs[0].whole_session);
  EXPECT_GE(held.runs[0].first, 596U);
  EXPECT_LE(held.runs[0].first, 599U);
  EXPECT_EQ(held.runs[0].end, w.size());
  EXPECT_NEAR(held.resolution_K, 0.1, 1e-9);
  EXPECT_EQ(readings(r), held.runs[0].first);
  EXPECT_TRUE(r.winding_sensor);
  EXPECT_NE(held.describe("T_winding").at(0).find("a held value, not a reading: not used"), std::string::npos);
}

// Live sensors are kept: exact, 0.1 K and 1 K readings of the heat-up, one lagging 30 s (τ_s known), and one at 1 K
// resting on 60 °C for an hour while r̂s's noise (σ 1 K, and 3 K) wanders — each over ten seeds. (14.28b) allows
// q + z·√(σ_k² + σ_0² + 2σ_s²) ≥ 1 + 4.9·2 K; r̂s's noise alone exceeds that with probability ≤ 10⁻³ per record.
TEST(HeldWindingColumn, LiveReadingsAreKept) {
  const std::vector<double> w = heat_up(1800), steady(3600, 60.0);
  for (unsigned seed = 1; seed <= 10; ++seed) {
    for (const double q : {0.0, 0.1, 1.0}) {
      ThermalRecord r = record_of(w, live_sensor(w, q, 0.0), 1.0, seed);
      EXPECT_TRUE(drop_held_winding_readings(r, kCopperLaw, kSensorSigma_K, 0.0).runs.empty()) << q << ' ' << seed;
    }
    ThermalRecord lagging = record_of(w, live_sensor(w, 0.1, 30.0), 1.0, seed);
    EXPECT_TRUE(drop_held_winding_readings(lagging, kCopperLaw, kSensorSigma_K, 30.0).runs.empty()) << seed;
    for (const double sigma_rs : {1.0, 3.0}) {
      ThermalRecord resting = record_of(steady, steady, sigma_rs, seed);
      EXPECT_TRUE(drop_held_winding_readings(resting, kCopperLaw, kSensorSigma_K, 0.0).runs.empty()) << seed;
      EXPECT_EQ(readings(resting), steady.size());
    }
  }
}

// The stated limit: where r̂s never adapts, nothing says the winding moved, and the column is kept as it is.
TEST(HeldWindingColumn, WhereRsNeverAdaptsNothingIsFound) {
  const std::vector<double> w = heat_up(1800);
  ThermalRecord r = record_of(w, std::vector<double>(w.size(), 0.0), 1.0, 3, false);
  EXPECT_TRUE(drop_held_winding_readings(r, kCopperLaw, kSensorSigma_K, 0.0).runs.empty());
  EXPECT_EQ(readings(r), w.size());
  EXPECT_TRUE(r.winding_sensor);
}

// A folder's sessions are judged each on its own: a second session held from its start loses its column alone.
TEST(HeldWindingColumn, EachSessionOnItsOwn) {
  const std::vector<double> w = heat_up(1200);
  std::vector<ThermalRecord> sessions;
  sessions.push_back(record_of(w, live_sensor(w, 0.1, 0.0), 1.0, 4));
  sessions.push_back(record_of(w, std::vector<double>(w.size(), 25.0), 1.0, 5));
  sessions[1].log = sessions[1].session_logs[0] = "second.csv";
  ThermalRecord r = join_sessions(std::move(sessions), "folder");
  const HeldWindingColumn held = drop_held_winding_readings(r, kCopperLaw, kSensorSigma_K, 0.0);
  ASSERT_EQ(held.runs.size(), 1U);
  EXPECT_EQ(held.runs[0].first, w.size());
  EXPECT_TRUE(held.runs[0].whole_session);
  EXPECT_EQ(held.runs[0].log, "second.csv");
  EXPECT_EQ(readings(r), w.size());
  EXPECT_TRUE(r.winding_sensor);
}

/// The paper's three-node network (tests/support/paper_thermal.hpp) soaked at 25 °C, its winding under 10 A for
/// `heated_steps` 1 s steps and then at rest, with no r̂s observation; the winding node's temperature per step.
struct NetworkRide {
  core::ThermalFusionConfig fusion = test::paper_thermal_fusion();
  std::vector<core::ThermalLoad> loads;
  std::vector<double> winding_C;
};
NetworkRide network_ride(std::size_t steps, std::size_t heated_steps) {
  NetworkRide ride;
  const core::ThermalNetwork& n = ride.fusion.filter.network;
  core::ThermalVec t = core::ThermalVec::Constant(25.0);
  for (std::size_t k = 0; k < steps; ++k) {
    core::ThermalLoad l;
    l.dt_s = 1.0;
    l.current_sq_A2 = k < heated_steps ? 100.0 : 0.0;
    l.coolant_C = 25.0;
    const core::ThermalTransition tr = core::thermal_transition(n, l);
    t = tr.phi * t + tr.gamma;
    ride.loads.push_back(l);
    ride.winding_C.push_back(t[n.winding]);
  }
  return ride;
}

ThermalRecord record_of(const NetworkRide& ride, const std::vector<double>& reading_C) {
  ThermalRecord r = record_of(ride.winding_C, reading_C, 1.0, 1, false);
  for (std::size_t k = 0; k < r.steps.size(); ++k) {
    r.steps[k].load = ride.loads[k];
    r.steps[k].t_ns = static_cast<std::int64_t>(k + 1) * 1000000000;
  }
  return r;
}

// Eq. 14.28c. A 0.1 K sensor stuck 10 min into 20 min at 10 A (the winding 25 → 36.9 °C, at 36.6 °C then) while the
// winding cools for 20 min at rest (to 25.1 °C): once the current stops the network moves the winding beyond the
// filter's gate, the filter refuses the stuck value, and the whole run of that value goes — from the step the live
// sensor first read it (the run is that value's), to the end. A live 0.1 K reading of the same ride, and one resting
// on the soaked 25 °C for an hour with no load, lose nothing; a 0 °C on every step is no sensor.
TEST(HeldWindingColumn, TheFittedNetworkFindsAValueHeldWhereRsNeverAdapts) {
  const NetworkRide ride = network_ride(2400, 1200);
  ASSERT_GT(ride.winding_C[599] - ride.winding_C.back(), 10.0);  // what the held value hides
  std::vector<double> stuck = live_sensor(ride.winding_C, 0.1, 0.0);
  std::size_t came = 599;  // the step the live sensor first read the value it sticks on
  while (came > 0 && stuck[came - 1] == stuck[599]) --came;
  for (std::size_t k = 600; k < stuck.size(); ++k) stuck[k] = stuck[599];
  ThermalRecord r = record_of(ride, stuck);
  const HeldWindingColumn held = drop_winding_readings_the_network_holds(r, ride.fusion);
  ASSERT_EQ(held.runs.size(), 1U);
  EXPECT_EQ(held.runs[0].found_by, HeldWindingRun::FoundBy::kFittedNetwork);
  EXPECT_EQ(held.runs[0].first, came);
  EXPECT_EQ(held.runs[0].end, stuck.size());
  EXPECT_GT(held.runs[0].refused_steps, 0U);
  EXPECT_EQ(readings(r), held.runs[0].first);
  EXPECT_TRUE(r.winding_sensor);
  const std::vector<std::string> said = held.describe("T_winding");
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("the filter refused it as held on"), std::string::npos) << said[0];

  ThermalRecord live = record_of(ride, live_sensor(ride.winding_C, 0.1, 0.0));
  EXPECT_TRUE(drop_winding_readings_the_network_holds(live, ride.fusion).runs.empty());
  EXPECT_EQ(readings(live), ride.winding_C.size());

  const NetworkRide at_rest = network_ride(3600, 0);
  ThermalRecord resting = record_of(at_rest, std::vector<double>(3600, 25.0));
  EXPECT_TRUE(drop_winding_readings_the_network_holds(resting, at_rest.fusion).runs.empty());

  ThermalRecord disabled = record_of(ride, std::vector<double>(ride.winding_C.size(), 0.0));
  const HeldWindingColumn none = drop_winding_readings_the_network_holds(disabled, ride.fusion);
  ASSERT_EQ(none.runs.size(), 1U);
  EXPECT_TRUE(none.runs[0].whole_session);
  EXPECT_FALSE(disabled.winding_sensor);
}

}  // namespace
}  // namespace rpem::analysis
