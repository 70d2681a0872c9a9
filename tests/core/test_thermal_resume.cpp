// A restart of the thermal fusion from a saved state (core/thermal_resume.hpp, eq. 14.26): the network carried
// across the gap under no load and under the last load, against an RK4 integration of the network's heat balance
// written here from eq. 14.1 (the mean and, without noise, the covariance's dP/dt = A·P + P·Aᵀ), and the fusion's
// first step starting there — covering a machine that cooled and one that ran on, where a start at the coolant
// covers neither.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "rpem/core/thermal_fusion.hpp"
#include "rpem/core/thermal_resume.hpp"

namespace rpem::core {
namespace {

constexpr double kCoolant_C = 30.0;

/// Winding, stator iron, magnet: the winding and the magnet tied through the iron; no speed-dependent terms.
ThermalFilterConfig three_nodes() {
  ThermalFilterConfig c;
  ThermalNetwork& n = c.network;
  n.nodes = 3;
  n.winding = 0, n.magnet = 2;
  n.capacitance_J_per_K << 4000.0, 15000.0, 6000.0, 1.0;
  n.to_coolant_W_per_K << 3.0, 60.0, 5.0, 0.0;
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 25.0;
  n.between_W_per_K(1, 2) = n.between_W_per_K(2, 1) = 8.0;
  n.copper = {0.00393, 20.0, 0.05};
  n.base = {1000.0, 0.1, 100.0};
  n.loss_at_base_W(static_cast<int>(LossForm::kIronEddy), 1) = 2500.0;
  n.loss_at_base_W(static_cast<int>(LossForm::kMagnetEddy), 2) = 500.0;
  c.calibration_sigma.setZero();
  c.copper_rel_sigma = 0.0;
  return c;
}

/// The load the drive ran at: iron and magnet eddy losses at their base (2.5 kW and 0.5 kW: the magnet's steady
/// state 94.7 °C), no copper loss.
ThermalLoad running_load() {
  ThermalLoad l;
  l.basis = {0.0, 1.0, 1.0};
  l.coolant_C = kCoolant_C;
  return l;
}

ThermalSnapshot hot_snapshot() {
  ThermalSnapshot s;
  s.nodes = 3, s.winding = 0, s.magnet = 2;
  s.t_C << 95.0, 70.0, 88.0, 0.0;
  s.p_K2.diagonal() << 4.0, 2.0, 9.0, 0.0;
  s.p_K2(0, 2) = s.p_K2(2, 0) = 1.5;
  s.load = running_load();
  return s;
}

/// dT/dt of eq. 14.1 for the three nodes at losses `p_W` (written from the equation, not from thermal_network.cpp).
std::array<double, 3> heat_balance(const std::array<double, 3>& t, const std::array<double, 3>& p_W) {
  const double q01 = 25.0 * (t[0] - t[1]), q12 = 8.0 * (t[1] - t[2]);
  return {(p_W[0] - q01 - 3.0 * (t[0] - kCoolant_C)) / 4000.0, (p_W[1] + q01 - q12 - 60.0 * (t[1] - kCoolant_C)) / 15000.0,
          (p_W[2] + q12 - 5.0 * (t[2] - kCoolant_C)) / 6000.0};
}

std::array<double, 3> rk4(std::array<double, 3> t, const std::array<double, 3>& p_W, double duration_s) {
  const int steps = 20000;
  const double h = duration_s / steps;
  auto add = [](const std::array<double, 3>& a, const std::array<double, 3>& b, double k) {
    return std::array<double, 3>{a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]};
  };
  for (int s = 0; s < steps; ++s) {
    const auto k1 = heat_balance(t, p_W);
    const auto k2 = heat_balance(add(t, k1, h / 2), p_W);
    const auto k3 = heat_balance(add(t, k2, h / 2), p_W);
    const auto k4 = heat_balance(add(t, k3, h), p_W);
    for (int i = 0; i < 3; ++i) t[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  return t;
}

/// The covariance without noise, dP/dt = A·P + P·Aᵀ: each column of Φ is the unforced response to a unit
/// temperature (the coolant at 0), so P(t) = Φ·P₀·Φᵀ with Φ from three RK4 runs of the heat balance.
Eigen::Matrix3d propagated_covariance(const Eigen::Matrix3d& p0, double duration_s) {
  Eigen::Matrix3d phi;
  for (int j = 0; j < 3; ++j) {
    std::array<double, 3> e{kCoolant_C, kCoolant_C, kCoolant_C};
    e[static_cast<std::size_t>(j)] += 1.0;
    const auto r = rk4(e, {0.0, 0.0, 0.0}, duration_s);
    for (int i = 0; i < 3; ++i) phi(i, j) = r[static_cast<std::size_t>(i)] - kCoolant_C;
  }
  return phi * p0 * phi.transpose();
}

TEST(ThermalResume, NoGapIsTheSavedState) {
  const ThermalSnapshot s = hot_snapshot();
  const ThermalSnapshot r = across_unknown_load(three_nodes(), s, 0.0, 1.0);
  EXPECT_EQ(r.t_C, s.t_C);
  EXPECT_EQ(r.p_K2, s.p_K2);
}

// Mean and covariance of the mixture (eq. 14.26) against the two RK4-integrated ends, a gap of 1 234.5 s in steps
// of at most 2 s (618 steps of 1.9976 s: the transition is exact, so the step does not matter beyond rounding).
TEST(ThermalResume, TheGapIsTheEvenMixtureOfNoLoadAndTheLastLoad) {
  const ThermalSnapshot s = hot_snapshot();
  const double gap_s = 1234.5;
  const ThermalSnapshot r = across_unknown_load(three_nodes(), s, gap_s, 2.0);
  const std::array<double, 3> t0{95.0, 70.0, 88.0};
  const auto none = rk4(t0, {0.0, 0.0, 0.0}, gap_s);
  const auto ran = rk4(t0, {0.0, 2500.0, 500.0}, gap_s);
  const Eigen::Matrix3d p = propagated_covariance(s.p_K2.topLeftCorner<3, 3>(), gap_s);
  Eigen::Vector3d half;
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const auto k = static_cast<std::size_t>(i);
    half[i] = 0.5 * (ran[k] - none[k]);
    EXPECT_NEAR(r.t_C[i], 0.5 * (none[k] + ran[k]), 1e-6);
  }
  // Without noise both ends carry the same Φ·P₀·Φᵀ; the mixture adds the ends' spread.
  const Eigen::Matrix3d expected = p + half * half.transpose();
  EXPECT_LT((r.p_K2.topLeftCorner<3, 3>() - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.cwiseAbs().maxCoeff());
  // The magnet cooled by 50 K without load and warmed by 6 K with it (RK4: 37.7 and 94.4 °C): the spread matters.
  EXPECT_LT(none[2], 70.0);
  EXPECT_GT(ran[2], 85.0);
  // Either end within 1σ of the mean, so inside the 2σ band a supervisor derates on.
  for (int i = 0; i < 3; ++i) EXPECT_LE(std::abs(half[i]), std::sqrt(r.p_K2(i, i)) + 1e-9);
}

TEST(ThermalResume, OnlyTheNetworkItWasTakenOfResumesIt) {
  ThermalSnapshot s = hot_snapshot();
  const ThermalNetwork n = three_nodes().network;
  EXPECT_TRUE(fits_network(s, n));
  s.magnet = 1;
  EXPECT_FALSE(fits_network(s, n));
  s = hot_snapshot();
  s.nodes = 2;
  EXPECT_FALSE(fits_network(s, n));
  ThermalFusionConfig c;
  c.filter = three_nodes();
  ThermalFusion fusion(c, PerUnitBase{}, MachineSi{});
  EXPECT_FALSE(fusion.resume(s, 10.0));
  EXPECT_EQ(fusion.snapshot().nodes, 0);  // not started
}

// The fusion's first step after a restart 300 s on, the machine at standstill since: it starts where the saved
// state stands now, its band holding the magnet whether the drive stopped (RK4) or ran on; a start at the coolant
// (what a restart did before) is 38 K too cold with a 10 K band (RK4: 67.9 °C stopped, 91.3 °C ran on).
TEST(ThermalResume, TheFirstStepAfterARestartStartsWhereTheSavedStateStandsNow) {
  ThermalFusionConfig c;
  c.filter = three_nodes();
  c.filter.process_noise_K2_per_s.setConstant(1e-3);
  c.observer.period_s = 1.0;
  c.coolant_C = kCoolant_C;
  const ThermalSnapshot saved = hot_snapshot();
  const double gap_s = 300.0;
  ThermalStepData first;
  first.t_ns = 1'000'000'000;
  first.load.dt_s = 1.0;
  first.load.coolant_C = kCoolant_C;
  const std::array<double, 3> t0{95.0, 70.0, 88.0};
  const double stopped_C = rk4(t0, {0.0, 0.0, 0.0}, gap_s + 1.0)[2];
  const double ran_on_C = rk4(rk4(t0, {0.0, 2500.0, 500.0}, gap_s), {0.0, 0.0, 0.0}, 1.0)[2];

  ThermalFusion resumed(c, PerUnitBase{}, MachineSi{});
  ASSERT_TRUE(resumed.resume(saved, gap_s));
  resumed.apply(first);
  const ThermalNodeEstimate& m = resumed.estimate().magnet_node();
  for (const double truth_C : {stopped_C, ran_on_C}) EXPECT_LE(std::abs(m.t_C - truth_C), 2.0 * m.sigma_K);
  EXPECT_NEAR(m.t_C, 0.5 * (stopped_C + ran_on_C), 0.05);
  const ThermalSnapshot now = resumed.snapshot();
  EXPECT_EQ(now.nodes, 3);
  EXPECT_EQ(now.t_C, resumed.filter().temperature_C());

  ThermalFusion fresh(c, PerUnitBase{}, MachineSi{});
  fresh.apply(first);
  const ThermalNodeEstimate& cold = fresh.estimate().magnet_node();
  EXPECT_NEAR(cold.t_C, kCoolant_C, 0.01);
  EXPECT_GT(std::abs(cold.t_C - stopped_C), 2.0 * cold.sigma_K);
}

}  // namespace
}  // namespace rpem::core
