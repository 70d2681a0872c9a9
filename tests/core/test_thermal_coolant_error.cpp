// A coolant that moves unread (core/thermal_filter.hpp, docs/derivations.md eq. 14.29): the held reading's error e_c
// as a consider state that walks between readings. The nodes' added variance over a silence against two computations
// that share nothing with the filter's discrete step — the continuous Lyapunov equation of [T; e_c] integrated by RK4,
// and a Monte Carlo of the walk through an Euler-integrated plant — and against the bound q_c·s (a node's step
// response to the coolant lies in [0, 1]); a reading on every step changes nothing to the last bit, a reading after
// a silence starts e_c again, and a filter that never saw a reading does not widen. The winding's rate carries e_c
// (eq. 14.29a): every row built on it takes e_c as the coolant itself enters it, and the winding reported ahead of a
// reading node widens as the Lyapunov equation says along that row.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "rpem/core/thermal_fusion.hpp"
#include "rpem/core/thermal_sensor.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

constexpr double kQc_K2_per_s = 2e-3;

/// Two nodes with time constants of about 60 and 300 s, no loss at zero current.
ThermalFilterConfig coolant_test_network(double q_c) {
  ThermalFilterConfig c;
  ThermalNetwork& n = c.network;
  n.nodes = 2;
  n.capacitance_J_per_K << 2000.0, 4000.0, 1.0, 1.0;
  n.to_coolant_W_per_K << 20.0, 10.0, 0.0, 0.0;
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 10.0;
  n.copper = {0.00393, 20.0, 0.05};
  n.base = {1000.0, 0.1, 100.0};
  c.calibration_sigma.setZero();
  c.copper_rel_sigma = 0.0;
  c.coolant_drift_K2_per_s = q_c;
  return c;
}

ThermalLoad at_rest_load(double dt_s) {
  ThermalLoad l;
  l.dt_s = dt_s;
  l.coolant_C = 25.0;
  return l;
}

using CoolantMat3 = Eigen::Matrix3d;
using ThermalMat2N = Eigen::Matrix<double, kDynamicThermalStates, kDynamicThermalStates>;

/// dP/dt = M·P + P·Mᵀ + Q of z = [T₀, T₁, e_c], dT/dt = A·T + C⁻¹·g_c·e_c, de_c/dt = white of intensity q_c:
/// P(t) from P(0) = 0, by RK4 at `h_s`, sampled at whole seconds.
std::vector<CoolantMat3> coolant_lyapunov(const ThermalNetwork& n, double q_c, double seconds, double h_s) {
  CoolantMat3 m = CoolantMat3::Zero();
  for (int i = 0; i < 2; ++i) {
    const double c = n.capacitance_J_per_K[i], g0 = n.to_coolant_W_per_K[i], g = n.between_W_per_K(0, 1);
    m(i, i) = -(g0 + g) / c;
    m(i, 1 - i) = g / c;
    m(i, 2) = g0 / c;
  }
  CoolantMat3 q = CoolantMat3::Zero();
  q(2, 2) = q_c;
  const auto rate = [&](const CoolantMat3& p) -> CoolantMat3 { return m * p + p * m.transpose() + q; };
  std::vector<CoolantMat3> out{CoolantMat3::Zero()};
  CoolantMat3 p = CoolantMat3::Zero();
  const int per_second = static_cast<int>(std::lround(1.0 / h_s));
  for (int k = 1; k <= static_cast<int>(seconds) * per_second; ++k) {
    const CoolantMat3 k1 = rate(p), k2 = rate(p + 0.5 * h_s * k1), k3 = rate(p + 0.5 * h_s * k2), k4 = rate(p + h_s * k3);
    p += (h_s / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    if (k % per_second == 0) out.push_back(p);
  }
  return out;
}

TEST(ThermalCoolantError, NodesWidenAsTheContinuousLyapunovEquationSays) {
  ThermalFilter f(coolant_test_network(kQc_K2_per_s));
  f.reset(25.0, 0.0);
  f.coolant_read();  // the last reading: from here the coolant is unread
  const std::vector<CoolantMat3> truth = coolant_lyapunov(f.config().network, kQc_K2_per_s, 3000.0, 0.02);
  for (int s = 1; s <= 3000; ++s) {
    f.predict(at_rest_load(1.0));
    if (s != 60 && s != 600 && s != 3000) continue;
    // The filter holds e_c over each step at its start value (eq. 14.4's hold): it lags the continuous walk by half
    // a step, and P_TT grows as s³ at first (a walk through a lag), so the relative difference is about 1.5·Δt/s.
    const double tol_rel = 1.5 / s + 1e-3;
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(f.covariance()(i, i), truth[s](i, i), tol_rel * truth[s](i, i)) << "node " << i << " at " << s << " s";
      // The steady-state bound (eq. 14.29): a node's step response to the coolant lies in [0, 1], so a walk of
      // intensity q_c adds at most q_c·s to its variance.
      EXPECT_LE(f.covariance()(i, i), kQc_K2_per_s * s);
    }
    EXPECT_NEAR(f.covariance()(0, 1), truth[s](0, 1), tol_rel * truth[s](0, 1)) << s << " s";
  }
}

TEST(ThermalCoolantError, NodesWidenAsAMonteCarloOfTheWalkThroughTheNetwork) {
  // The true coolant walks (Euler–Maruyama at 0.1 s) and drives the network (Euler at 0.1 s); the filter holds the
  // newest reading. The sample covariance of the nodes' error after 600 s against the filter's: 1000 runs, whose
  // sample variance has a relative standard error of √(2/1000) = 4.5 %, so 5 standard errors are 22 %.
  const ThermalFilterConfig c = coolant_test_network(kQc_K2_per_s);
  ThermalFilter f(c);
  f.reset(25.0, 0.0);
  f.coolant_read();
  constexpr int kSeconds = 600, kRuns = 1000, kPerSecond = 10;
  for (int s = 0; s < kSeconds; ++s) f.predict(at_rest_load(1.0));
  const ThermalNetwork& n = c.network;
  const double h = 1.0 / kPerSecond, g = n.between_W_per_K(0, 1);
  std::mt19937_64 rng(2912);
  std::normal_distribution<double> normal(0.0, std::sqrt(kQc_K2_per_s * h));
  Eigen::Matrix2d sum_sq = Eigen::Matrix2d::Zero();
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int run = 0; run < kRuns; ++run) {
    Eigen::Vector2d t(25.0, 25.0);
    double coolant = 25.0;
    for (int k = 0; k < kSeconds * kPerSecond; ++k) {
      Eigen::Vector2d dt_dt;
      for (int i = 0; i < 2; ++i)
        dt_dt[i] = (n.to_coolant_W_per_K[i] * (coolant - t[i]) + g * (t[1 - i] - t[i])) / n.capacitance_J_per_K[i];
      t += h * dt_dt;
      coolant += normal(rng);
    }
    const Eigen::Vector2d error = t - f.temperature_C().head<2>();
    sum += error;
    sum_sq += error * error.transpose();
  }
  const Eigen::Vector2d mean = sum / kRuns;
  const Eigen::Matrix2d sample = (sum_sq - kRuns * mean * mean.transpose()) / (kRuns - 1);
  for (int i = 0; i < 2; ++i) {
    const double p = f.covariance()(i, i);
    EXPECT_NEAR(sample(i, i), p, 0.22 * p) << "node " << i;
    EXPECT_NEAR(mean[i], 0.0, 5.0 * std::sqrt(p / kRuns)) << "node " << i;  // the held reading is unbiased
  }
}

TEST(ThermalCoolantError, AReadingOnEveryStepChangesNothingToTheLastBit) {
  ThermalFilterConfig c = coolant_test_network(0.5);  // a walk far faster than any coolant
  c.process_noise_K2_per_s << 1e-3, 2e-3, 0.0, 0.0;
  c.disturbance_W2_per_s << 0.5, 0.5, 0.0, 0.0;
  ThermalFilterConfig exact = c;
  exact.coolant_drift_K2_per_s = 0.0;
  ThermalFilter walking(c), held(exact);
  walking.reset(30.0, 3.0);
  held.reset(30.0, 3.0);
  ThermalObservation magnet;
  magnet.h[1] = 1.0;
  magnet.variance = 0.3;
  for (int k = 0; k < 200; ++k) {
    ThermalLoad l = at_rest_load(1.0);
    l.current_sq_A2 = 400.0 * (k % 7);
    l.convection_basis = 0.1 * (k % 5);
    walking.predict(l);
    held.predict(l);
    walking.coolant_read();
    held.coolant_read();
    magnet.value = 31.0 + 0.01 * k;
    ASSERT_EQ(walking.observe(magnet), held.observe(magnet));
    ASSERT_TRUE(walking.covariance() == held.covariance()) << "step " << k;
    ASSERT_TRUE(walking.temperature_C() == held.temperature_C()) << "step " << k;
  }
}

TEST(ThermalCoolantError, NoReadingYetMeansNoWalkAndAReadingStartsItAgain) {
  ThermalFilter walking(coolant_test_network(kQc_K2_per_s)), held(coolant_test_network(0.0));
  walking.reset(25.0, 1.0);
  held.reset(25.0, 1.0);
  // Before any reading the configured coolant stands in: the no-coolant-column case keeps its own failure mode.
  for (int k = 0; k < 100; ++k) {
    walking.predict(at_rest_load(1.0));
    held.predict(at_rest_load(1.0));
  }
  ASSERT_TRUE(walking.covariance() == held.covariance());
  walking.coolant_read();
  for (int k = 0; k < 300; ++k) {
    walking.predict(at_rest_load(1.0));
    held.predict(at_rest_load(1.0));
  }
  const int ke = kDynamicThermalStates + static_cast<int>(Calibration::kCoolantError);
  const ThermalStateMat silent = walking.covariance();
  EXPECT_NEAR(silent(ke, ke), kQc_K2_per_s * 300.0, 1e-12);
  EXPECT_GT(silent(1, 1), held.covariance()(1, 1));
  // A reading: e_c is the reading's own error, independent of all before — its row and column go, P_TT stays.
  walking.coolant_read();
  EXPECT_TRUE(walking.covariance().row(ke).isZero(0.0));
  EXPECT_TRUE(walking.covariance().col(ke).isZero(0.0));
  const auto dynamic_block = [](const ThermalStateMat& p) {
    return ThermalMat2N(p.topLeftCorner<kDynamicThermalStates, kDynamicThermalStates>());
  };
  EXPECT_TRUE(dynamic_block(walking.covariance()) == dynamic_block(silent));
}

/// ThermalFusion end to end on `steps` recorded steps at rest, 1 s each, the coolant read on the first `read_steps`
/// (no observation valid: the band is the prediction's); the estimate at the end.
ThermalEstimate fused_at_rest(const ThermalFusionConfig& config, int steps, int read_steps) {
  ThermalFusion fusion(config, test::paper_base(), test::paper_machine_si());
  for (int k = 0; k < steps; ++k) {
    ThermalStepData d;
    d.t_ns = static_cast<std::int64_t>(k + 1) * 1'000'000'000;
    d.load = at_rest_load(1.0);
    d.coolant_read = k < read_steps;
    fusion.apply(d);
  }
  return fusion.estimate();
}

TEST(ThermalCoolantError, ASilentCoolantSensorWidensTheFusedBandBoundedByTheCoolantsOwnWalk) {
  ThermalFusionConfig c;
  c.filter = coolant_test_network(kQc_K2_per_s);
  c.initial_sigma_K = 1.0;
  ThermalFusionConfig exact = c;
  exact.filter.coolant_drift_K2_per_s = 0.0;
  constexpr int kSteps = 2100, kRead = 300;
  const auto run = [&](const ThermalFusionConfig& config, int read_steps) {
    return fused_at_rest(config, kSteps, read_steps).magnet_node().sigma_K;
  };
  const double exact_sigma = run(exact, kSteps);
  EXPECT_EQ(run(c, kSteps), exact_sigma);  // read on every step: the same band
  const double silent_sigma = run(c, kRead);
  const double added_K2 = silent_sigma * silent_sigma - exact_sigma * exact_sigma;
  // P_TT's propagation is linear and no observation comes, so the walk adds what it adds from zero: the continuous
  // Lyapunov equation's after the kSteps − kRead predictions since the last reading, within the hold's half step.
  constexpr int kUnread = kSteps - kRead;
  const std::vector<CoolantMat3> truth = coolant_lyapunov(c.filter.network, kQc_K2_per_s, kUnread, 0.02);
  EXPECT_NEAR(added_K2, truth[kUnread](1, 1), (1.5 / kUnread + 1e-3) * truth[kUnread](1, 1));
  EXPECT_LE(added_K2, kQc_K2_per_s * kUnread);  // never more than the coolant's whole walk (eq. 14.29)
}

/// A fusion configuration over coolant_test_network with a winding sensor of τ_s = 8 s; the winding's coolant
/// conductance also grows with speed, so g_c,w depends on the load (eq. 14.1b).
ThermalFusionConfig coolant_sensor_config(bool node_is_reading) {
  ThermalFusionConfig c;
  c.filter = coolant_test_network(kQc_K2_per_s);
  c.filter.network.to_coolant_at_base_speed_W_per_K[0] = 5.0;
  c.initial_sigma_K = 1.0;
  c.winding_sensor_sigma_K = 0.1;
  c.winding_sensor_time_constant_s = 8.0;
  c.winding_node_is_reading = node_is_reading;
  return c;
}

TEST(ThermalCoolantError, TheCoolantErrorEntersEveryRateRowAsTheCoolantItselfDoes) {
  // e_c is the true coolant less the held reading, so wherever the winding's rate enters a row — a lagging sensor's
  // mean reading (eq. 14.22), the winding that leads a reading node and the parameter observations read through it
  // (eq. 14.24) — e_c's coefficient is the row's derivative with respect to the held coolant (eq. 14.29a). The
  // offsets are linear in the coolant, so a difference of one kelvin is that derivative exactly, to rounding.
  const int ke = static_cast<int>(Calibration::kCoolantError);
  const ThermalVec t_C(40.0, 35.0, 0.0, 0.0);
  for (const bool node_is_reading : {false, true}) {
    const ThermalFusionConfig c = coolant_sensor_config(node_is_reading);
    ThermalStepData d;
    d.load = at_rest_load(1.0);
    d.load.current_sq_A2 = 2500.0;
    d.load.convection_basis = 0.6;
    d.winding_sensor_C = 38.0;
    d.winding_sensor_age = {0.25, 0.0625};
    d.parameter[1].valid = true;  // r̂s adapting: an observation of the winding
    d.parameter[1].value = 0.055;
    d.parameter[1].variance = 1e-8;
    ThermalStepData warmer = d;
    warmer.load.coolant_C += 1.0;
    const StepObservations o = step_observations(c, d, t_C, ThermalVec::Zero());
    const StepObservations o1 = step_observations(c, warmer, t_C, ThermalVec::Zero());
    ASSERT_TRUE(o.present[1] && o.present[2]);
    for (std::size_t k : {std::size_t{1}, std::size_t{2}}) {
      const double derivative = o1.item[k].offset - o.item[k].offset;
      EXPECT_NEAR(o.item[k].h_c[ke], derivative, 1e-12 * std::max(1.0, std::abs(o.item[k].offset)))
          << (node_is_reading ? "reading node, " : "lagging sensor, ") << "observation " << k;
    }
    const WindingReadout g = winding_readout(c, thermal_rates(c.filter.network, d.load));
    const WindingReadout g1 = winding_readout(c, thermal_rates(c.filter.network, warmer.load));
    EXPECT_NEAR(g.row[kDynamicThermalStates + ke], g1.constant_K - g.constant_K, 1e-12 * std::abs(g.constant_K));
    // Where the rate enters — the lagging sensor; r̂s through the reading node — the term is there and has the rate's
    // sign: a warmer coolant than read heats the winding, so a lagging sensor reads less of it now (−κ·G_w0/C_w) and
    // the winding leads the reading node by more (+τ_s·G_w0/C_w).
    const double g_w0 = 20.0 + 5.0 * 0.6, c_w = 2000.0;
    if (node_is_reading) {
      EXPECT_NEAR(g.row[kDynamicThermalStates + ke], 8.0 * g_w0 / c_w, 1e-15);
      EXPECT_GT(o.item[1].h_c[ke], 0.0);
      EXPECT_EQ(o.item[2].h_c[ke], 0.0);  // the sensor observes the reading node as it is
    } else {
      EXPECT_EQ(g.row[kDynamicThermalStates + ke], 0.0);
      const double kappa_s = sensor_lag_step(8.0, 1.0, d.winding_sensor_age).rate_s;  // κ of eq. 14.22
      EXPECT_NEAR(o.item[2].h_c[ke], -kappa_s * g_w0 / c_w, 1e-15);
      EXPECT_LT(o.item[2].h_c[ke], 0.0);
      EXPECT_EQ(o.item[1].h_c[ke], 0.0);  // r̂s sees the winding node itself
    }
  }
}

TEST(ThermalCoolantError, TheReportedWindingLedByItsRateWidensAsTheLyapunovEquationSays) {
  // The winding node standing for a reading (eq. 14.24): the reported winding is T_0 + τ_s·dT_0/dt, whose rate holds
  // the coolant's error (eq. 14.29a). Its added variance over a silence against the continuous Lyapunov equation of
  // [T; e_c], read along the row e_0 + τ_s·(dT_0/dt's row) formed here from the network's conductances.
  ThermalFusionConfig c = coolant_sensor_config(true);
  c.filter.network.to_coolant_at_base_speed_W_per_K[0] = 0.0;  // the Lyapunov helper's network: no speed term
  ThermalFusionConfig exact = c;
  exact.filter.coolant_drift_K2_per_s = 0.0;
  constexpr int kSteps = 2100, kRead = 300;
  const auto run = [&](const ThermalFusionConfig& config) { return fused_at_rest(config, kSteps, kRead).node[0].sigma_K; };
  const double exact_sigma = run(exact), silent_sigma = run(c);
  const double added_K2 = silent_sigma * silent_sigma - exact_sigma * exact_sigma;
  constexpr int kUnread = kSteps - kRead;
  const ThermalNetwork& n = c.filter.network;
  const std::vector<CoolantMat3> truth = coolant_lyapunov(n, kQc_K2_per_s, kUnread, 0.02);
  const double tau = c.winding_sensor_time_constant_s, c0 = n.capacitance_J_per_K[0];
  const double g0 = n.to_coolant_W_per_K[0], g01 = n.between_W_per_K(0, 1);
  const Eigen::Vector3d row(1.0 - tau * (g0 + g01) / c0, tau * g01 / c0, tau * g0 / c0);
  const double expected = row.dot(truth[kUnread] * row);
  EXPECT_NEAR(added_K2, expected, (1.5 / kUnread + 1e-3) * expected);
  // Without e_c in the rate the same row would stop at the nodes: a different figure, by more than the tolerance.
  const Eigen::Vector3d nodes_only(row[0], row[1], 0.0);
  EXPECT_GT(std::abs(nodes_only.dot(truth[kUnread] * nodes_only) - expected), 0.01 * expected);
}

}  // namespace
}  // namespace rpem::core
