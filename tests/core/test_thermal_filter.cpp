// The thermal Kalman filter (core/thermal_filter.hpp, docs/derivations.md §14) against hand-worked updates
// and closed-form limits: the scalar update, a correlated update, Schmidt's consider states (the calibration
// bounds what observations can teach), the gate, the prediction's covariance, and a heat disturbance the
// filter learns from observations of one node; the blockwise prediction and sparse update against the dense
// forms on all thirteen states; a law's bilinear calibration term taken over the prior (eq. 14.10a).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "rpem/core/thermal_filter.hpp"
#include "rpem/core/thermal_fusion.hpp"

namespace rpem::core {
namespace {

ThermalFilterConfig two_nodes() {
  ThermalFilterConfig c;
  ThermalNetwork& n = c.network;
  n.nodes = 2;
  n.capacitance_J_per_K << 5000.0, 20000.0, 1.0, 1.0;
  n.to_coolant_W_per_K << 30.0, 8.0, 0.0, 0.0;
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 10.0;
  n.copper = {0.00393, 20.0, 0.05};
  n.base = {1000.0, 0.1, 100.0};
  c.calibration_sigma.setZero();
  c.copper_rel_sigma = 0.0;
  return c;
}

ThermalObservation magnet_reading(double value, double variance) {
  ThermalObservation o;
  o.h[1] = 1.0;
  o.value = value;
  o.variance = variance;
  return o;
}

TEST(ThermalFilter, ScalarAndCorrelatedUpdatesAreTheHandWorkedOnes) {
  ThermalFilter f(two_nodes());
  ThermalMat p = ThermalMat::Zero();
  p(0, 0) = 4.0, p(1, 1) = 9.0;
  f.set_temperatures(ThermalVec(50.0, 40.0, 0.0, 0.0), p);
  ASSERT_EQ(f.observe(magnet_reading(43.0, 1.0)), ObservationResult::kAccepted);
  EXPECT_NEAR(f.temperature_C()[1], 40.0 + 0.9 * 3.0, 1e-12);  // K = 9/(9 + 1)
  EXPECT_NEAR(f.temperature_C()[0], 50.0, 1e-12);              // uncorrelated: untouched
  EXPECT_NEAR(f.covariance()(1, 1), 0.9, 1e-12);
  // Correlated: P = [[4, 3], [3, 9]] → K = [3, 9]/10, P⁺ = P − [3, 9]·[3, 9]ᵀ/10.
  p(0, 1) = p(1, 0) = 3.0;
  f.set_temperatures(ThermalVec(50.0, 40.0, 0.0, 0.0), p);
  ASSERT_EQ(f.observe(magnet_reading(43.0, 1.0)), ObservationResult::kAccepted);
  EXPECT_NEAR(f.temperature_C()[0], 50.0 + 0.3 * 3.0, 1e-12);
  EXPECT_NEAR(f.temperature_C()[1], 40.0 + 0.9 * 3.0, 1e-12);
  EXPECT_NEAR(f.covariance()(0, 0), 3.1, 1e-12);
  EXPECT_NEAR(f.covariance()(0, 1), 0.3, 1e-12);
  EXPECT_NEAR(f.covariance()(1, 1), 0.9, 1e-12);
  EXPECT_NEAR(f.last_innovation(), 3.0, 1e-12);
  EXPECT_NEAR(f.last_innovation_variance(), 10.0, 1e-12);
}

TEST(ThermalFilter, CalibrationItCannotLearnBoundsWhatObservationsTeach) {
  // y = T_m + e_ref + v with e_ref a consider state of σ 2 K: the fixed point of Schmidt's update has
  // P_TT = σ² — a thousand readings leave the magnet known to the calibration's 2 K, not to 1/√1000.
  ThermalFilterConfig c = two_nodes();
  c.calibration_sigma[static_cast<int>(Calibration::kMagnetOffset)] = 2.0;
  ThermalFilter f(c);
  f.reset(25.0, 10.0);
  ThermalObservation o = magnet_reading(60.0, 1.0);
  o.h_c[static_cast<int>(Calibration::kMagnetOffset)] = 1.0;
  for (int k = 0; k < 2000; ++k) ASSERT_NE(f.observe(o), ObservationResult::kRejectedInvalid);
  EXPECT_NEAR(f.sigma_K(1), 2.0, 0.02);
  EXPECT_NEAR(f.temperature_C()[1], 60.0, 0.05);  // the readings' mean: the calibration is not estimated
  // The same without the consider state: the noise alone, averaged.
  ThermalFilter g(two_nodes());
  g.reset(25.0, 10.0);
  for (int k = 0; k < 2000; ++k) ASSERT_NE(g.observe(magnet_reading(60.0, 1.0)), ObservationResult::kRejectedInvalid);
  EXPECT_NEAR(g.sigma_K(1), std::sqrt(1.0 / 2000.0), 1e-3);
}

TEST(ThermalFilter, GateRejectsAnInnovationBeyondItsSigmas) {
  ThermalFilterConfig c = two_nodes();
  c.gate_sigma = 5.0;
  ThermalFilter f(c);
  f.reset(30.0, 1.0);  // s = 1 + 1 = 2: the gate at 5·√2 = 7.07 K
  EXPECT_EQ(f.observe(magnet_reading(37.2, 1.0)), ObservationResult::kRejectedGate);
  EXPECT_NEAR(f.temperature_C()[1], 30.0, 0.0);
  EXPECT_EQ(f.observe(magnet_reading(37.0, 1.0)), ObservationResult::kAccepted);
  EXPECT_EQ(f.observe(magnet_reading(std::nan(""), 1.0)), ObservationResult::kRejectedInvalid);
  EXPECT_EQ(f.observe(magnet_reading(30.0, 0.0)), ObservationResult::kRejectedInvalid);
}

TEST(ThermalFilter, PredictionIsTheNetworkStepAndPropagatesTheCovariance) {
  const ThermalFilterConfig c = two_nodes();
  ThermalFilter f(c);
  ThermalMat p = ThermalMat::Zero();
  p(0, 0) = 4.0, p(1, 1) = 1.0, p(0, 1) = p(1, 0) = 0.5;
  const ThermalVec t0(80.0, 60.0, 0.0, 0.0);
  f.set_temperatures(t0, p);
  ThermalLoad l;
  l.dt_s = 10.0;
  l.current_sq_A2 = 100.0 * 100.0;
  l.coolant_C = 25.0;
  f.predict(l);
  const ThermalTransition tr = thermal_transition(c.network, l);
  const ThermalVec t1 = tr.phi * t0 + tr.gamma;
  EXPECT_LT((f.temperature_C() - t1).cwiseAbs().maxCoeff(), 1e-12);
  const ThermalMat p1 = tr.phi * p * tr.phi.transpose();  // no noise, no disturbance: Φ·P·Φᵀ
  EXPECT_LT((f.covariance().topLeftCorner<4, 4>() - p1).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ThermalFilter, LearnsAHeatDisturbanceFromOneNodesReadingsAndCorrectsTheOther) {
  // The true machine's magnet takes 400 W more than the model's; the filter reads the magnet only.
  ThermalFilterConfig c = two_nodes();
  c.loss_rel_sigma(static_cast<int>(LossForm::kMagnetEddy), 1) = 1.0;
  c.network.loss_at_base_W(static_cast<int>(LossForm::kMagnetEddy), 1) = 40.0;
  c.disturbance_W2_per_s << 10.0, 10.0, 0.0, 0.0;
  c.process_noise_K2_per_s << 1e-4, 1e-4, 0.0, 0.0;
  ThermalNetwork truth = c.network;
  truth.loss_at_base_W(static_cast<int>(LossForm::kMagnetEddy), 1) = 440.0;
  ThermalFilter f(c);
  f.reset(25.0, 0.5);
  ThermalLoad l;
  l.dt_s = 5.0;
  l.current_sq_A2 = 120.0 * 120.0;
  l.coolant_C = 25.0;
  l.basis[static_cast<std::size_t>(LossForm::kMagnetEddy)] = 1.0;
  ThermalVec t = ThermalVec::Constant(25.0);
  for (int k = 0; k < 4000; ++k) {  // 5.5 h: several of the magnet's time constants (C/G ≈ 20000/18 s)
    const ThermalTransition tr = thermal_transition(truth, l);
    t = tr.phi * t + tr.gamma;
    f.predict(l);
    (void)f.observe(magnet_reading(t[1], 0.25));
  }
  EXPECT_NEAR(f.disturbance_W()[1], 400.0, 20.0);
  EXPECT_NEAR(f.temperature_C()[1], t[1], 0.5);
  // The winding, never read, follows through the conductance between them. The model alone misses it by
  // ΔT_w = G_wm·ΔP/det, det = (G_w + G_wm − b)·(G_m + G_wm) − G_wm², b = (3/2)·i²·R_ref·α (the copper's
  // own feedback): 7.4 K. The filter's estimate is within 1 K.
  const double b = 1.5 * l.current_sq_A2 * 0.05 * 0.00393;
  const double det = (30.0 + 10.0 - b) * (8.0 + 10.0) - 100.0;
  const double model_miss = 10.0 * 400.0 / det;
  EXPECT_NEAR(thermal_steady_state(truth, l)[0] - thermal_steady_state(c.network, l)[0], model_miss, 1e-6);
  EXPECT_GT(model_miss, 7.0);
  EXPECT_NEAR(f.temperature_C()[0], t[0], 1.0);
}

// The filter predicts blockwise and updates with a sparse H (docs/derivations.md §14, eq. 14.11, 14.12, 14.21);
// here the dense forms on all 13 states: P⁺ = F·P·Fᵀ + Q_d with F = [Φ Γ_d b; 0 A 0; 0 0 I], A = diag(e^{−Δt/τ_d}),
// b = Γ_d·g_c in the coolant error's column (eq. 14.29), Q_d's coolant entry q_c·Δt,
// and the Joseph form (I − K·H)·P·(I − K·H)ᵀ + K·r·Kᵀ with K = [P·Hᵀ/s on T and d; 0 on c]. Four nodes in use, so
// every row of the network moves, with a disturbance and cross-covariances built by earlier steps.
void expect_blockwise_steps_are_the_dense_formulas(const ThermalVec& tau_s) {
  ThermalFilterConfig c;
  c.disturbance_time_constant_s = tau_s;
  ThermalNetwork& n = c.network;
  n.nodes = 4;
  n.winding = 0, n.magnet = 3;
  n.capacitance_J_per_K << 3000.0, 12000.0, 5000.0, 7000.0;
  n.to_coolant_W_per_K << 2.0, 90.0, 10.0, 4.0;
  n.to_coolant_at_base_speed_W_per_K[3] = 6.0;  // g_c's speed part (eq. 14.1b)
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 40.0;
  n.between_W_per_K(1, 2) = n.between_W_per_K(2, 1) = 25.0;
  n.between_W_per_K(2, 3) = n.between_W_per_K(3, 2) = 12.0;
  n.between_W_per_K(0, 3) = n.between_W_per_K(3, 0) = 3.0;
  n.copper = {0.00393, 20.0, 2.25};
  n.base = {1000.0, 0.1, 100.0};
  n.loss_at_base_W(static_cast<int>(LossForm::kIronEddy), 1) = 100.0;
  c.process_noise_K2_per_s << 1e-3, 2e-3, 3e-3, 4e-3;
  c.disturbance_W2_per_s << 1.0, 2.0, 3.0, 4.0;
  c.copper_rel_sigma = 0.0;  // Var(v) = q_d·Δt: the loss terms' changes are not what this test is about
  c.gate_sigma = 100.0;
  c.coolant_drift_K2_per_s = 0.05;
  ThermalFilter f(c);
  f.reset(40.0, 5.0);
  f.coolant_read();  // then unread: e_c walks through every step below and correlates with [T; d]
  ThermalLoad l;
  l.dt_s = 7.0;
  l.convection_basis = 0.6;
  l.current_sq_A2 = 900.0;
  l.basis[static_cast<std::size_t>(LossForm::kIronEddy)] = 0.5;
  l.coolant_C = 30.0;
  ThermalObservation magnet;  // the magnet through a law with its calibration states, and the winding
  magnet.h << 0.1, 0.0, 0.0, -1.4e-3;
  magnet.h_c << -1.4e-3, -0.04, 0.0, 0.0, 0.0;
  magnet.offset = 1.2;
  magnet.variance = 1e-6;
  ThermalObservation winding;
  winding.h[0] = 1.0;
  winding.variance = 0.5;
  for (int k = 0; k < 5; ++k) {  // cross-covariances everywhere, the state off its start
    f.predict(l);
    magnet.value = magnet.h.dot(f.temperature_C()) + magnet.offset + 2e-3;
    winding.value = f.temperature_C()[0] + 1.5;
    ASSERT_EQ(f.observe(magnet), ObservationResult::kAccepted);
    ASSERT_EQ(f.observe(winding), ObservationResult::kAccepted);
  }
  const auto state = [&f] {
    ThermalStateVec x = ThermalStateVec::Zero();
    x << f.temperature_C(), f.disturbance_W(), CalibrationVec::Zero();
    return x;
  };
  const ThermalStateVec x0 = state();
  const ThermalStateMat p0 = f.covariance();
  ASSERT_GT((p0.block<4, 4>(0, 4).cwiseAbs().minCoeff()), 0.0);  // T and d correlated: the blocks matter
  ASSERT_GT((p0.block<kMaxThermalNodes, kCalibrationStates>(0, kDynamicThermalStates).cwiseAbs().maxCoeff()), 0.0);
  const int ke = kDynamicThermalStates + static_cast<int>(Calibration::kCoolantError);
  ASSERT_GT(p0.col(ke).head<4>().cwiseAbs().minCoeff(), 0.0);  // the coolant's error reached every node
  EXPECT_TRUE(p0 == p0.transpose());

  f.predict(l);
  const ThermalTransition tr = thermal_transition(n, l);
  ThermalStateMat big_f = ThermalStateMat::Identity();
  big_f.block<4, 4>(0, 0) = tr.phi;
  big_f.block<4, 4>(0, 4) = tr.gamma_d;
  ThermalVec g_c = n.to_coolant_W_per_K + n.to_coolant_at_base_speed_W_per_K * 0.6;
  big_f.block<4, 1>(0, ke) = tr.gamma_d * g_c;
  ThermalVec drift_var = c.disturbance_W2_per_s * l.dt_s;  // eq. 14.9, and 14.20 where τ_d is finite
  for (int i = 0; i < 4; ++i) {
    if (std::isinf(tau_s[i])) continue;
    const double a = std::exp(-l.dt_s / tau_s[i]);
    big_f(4 + i, 4 + i) = a;
    drift_var[i] = c.disturbance_W2_per_s[i] * 0.5 * tau_s[i] * (1.0 - a * a);
  }
  ThermalStateMat q_d = ThermalStateMat::Zero();
  const ThermalMat q_t = c.process_noise_K2_per_s.asDiagonal();
  q_d.block<4, 4>(0, 0) = 0.5 * l.dt_s * (tr.phi * q_t * tr.phi.transpose() + q_t);
  q_d.block<4, 4>(4, 4) = drift_var.asDiagonal();
  q_d(ke, ke) = c.coolant_drift_K2_per_s * l.dt_s;
  const ThermalStateMat p1 = big_f * p0 * big_f.transpose() + q_d;
  ThermalStateVec x1 = big_f * x0;
  x1.head<4>() += tr.gamma;
  const double tol_p = 1e-13 * p1.cwiseAbs().maxCoeff();
  EXPECT_LT((f.covariance() - p1).cwiseAbs().maxCoeff(), tol_p);
  EXPECT_LT((state() - x1).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(f.covariance() == f.covariance().transpose());

  magnet.value = magnet.h.dot(f.temperature_C()) + magnet.offset - 3e-3;
  ThermalStateVec h = ThermalStateVec::Zero();
  h << magnet.h, ThermalVec::Zero(), magnet.h_c;
  const double s = h.dot(p1 * h) + magnet.variance;
  ThermalStateVec k = p1 * h / s;
  k.tail<kCalibrationStates>().setZero();  // Schmidt: the calibration states are considered, not estimated
  const ThermalStateMat i_kh = ThermalStateMat::Identity() - k * h.transpose();
  const ThermalStateMat p2 = i_kh * p1 * i_kh.transpose() + k * magnet.variance * k.transpose();
  const ThermalStateVec x2 = x1 + k * (magnet.value - h.dot(x1) - magnet.offset);
  ASSERT_EQ(f.observe(magnet), ObservationResult::kAccepted);
  EXPECT_NEAR(f.last_innovation_variance(), s, 1e-13 * s);
  EXPECT_LT((f.covariance() - p2).cwiseAbs().maxCoeff(), tol_p);
  EXPECT_LT((state() - x2).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(f.covariance() == f.covariance().transpose());
}

TEST(ThermalFilter, BlockwiseStepsAreTheDenseFormulasAndKeepPExactlySymmetric) {
  expect_blockwise_steps_are_the_dense_formulas(ThermalVec::Constant(std::numeric_limits<double>::infinity()));
}

TEST(ThermalFilter, BlockwiseStepsAreTheDenseFormulasWithGaussMarkovDisturbances) {
  // Eq. 14.21: Δt = 7 s against τ_d from 20 s (a = 0.70, far from the walk) to 10⁴ s, one node a walk.
  expect_blockwise_steps_are_the_dense_formulas(ThermalVec(20.0, 300.0, 1e4, std::numeric_limits<double>::infinity()));
}

TEST(ThermalFilter, GaussMarkovDisturbanceHasTheClosedFormVarianceAndCorrelation) {
  // Eq. 14.19, 14.20: unobserved, d's variance from zero after k steps is σ_d²·(1 − a^{2k}), σ_d² = q_d·τ_d/2,
  // for any step Δt (the discretisation is exact: two steps of Δt are one of 2Δt), and a learnt mean decays as
  // a^k = e^{−kΔt/τ_d}: the autocorrelation of the stationary process at lag kΔt. Both to rounding (1e-12).
  ThermalFilterConfig c = two_nodes();
  c.disturbance_W2_per_s << 10.0, 4.0, 0.0, 0.0;
  c.disturbance_time_constant_s << 600.0, 2400.0, 1.0, 1.0;
  const ThermalVec sigma2 = c.disturbance_W2_per_s.cwiseProduct(c.disturbance_time_constant_s) * 0.5;
  for (double dt : {1.0, 10.0, 60.0}) {
    ThermalFilter f(c);
    f.reset(25.0, 0.5);
    ThermalLoad l;
    l.dt_s = dt;
    l.coolant_C = 25.0;
    const int steps = static_cast<int>(std::lround(6000.0 / dt));
    for (int k = 0; k < steps; ++k) f.predict(l);
    for (int i = 0; i < 2; ++i) {
      const double expected = sigma2[i] * -std::expm1(-2.0 * 6000.0 / c.disturbance_time_constant_s[i]);
      EXPECT_NEAR(f.covariance()(kMaxThermalNodes + i, kMaxThermalNodes + i), expected, 1e-12 * expected)
          << "dt " << dt << " node " << i;
    }
  }
  // A learnt mean (the magnet's 400 W of the test above, read for 1 000 steps), then unobserved.
  ThermalNetwork truth = c.network;
  truth.loss_at_base_W(static_cast<int>(LossForm::kMagnetEddy), 1) = 400.0;
  ThermalFilterConfig learn = c;
  learn.disturbance_time_constant_s[1] = 1e5;
  ThermalFilter f(learn);
  f.reset(25.0, 0.5);
  ThermalLoad l;
  l.dt_s = 5.0;
  l.coolant_C = 25.0;
  l.basis[static_cast<std::size_t>(LossForm::kMagnetEddy)] = 1.0;
  ThermalVec t = ThermalVec::Constant(25.0);
  for (int k = 0; k < 1000; ++k) {
    const ThermalTransition tr = thermal_transition(truth, l);
    t = tr.phi * t + tr.gamma;
    f.predict(l);
    (void)f.observe(magnet_reading(t[1], 0.25));
  }
  const double d0 = f.disturbance_W()[1];
  const double p0 = f.covariance()(kMaxThermalNodes + 1, kMaxThermalNodes + 1);
  ASSERT_GT(d0, 100.0);
  f.reconfigure(c);  // τ_d = 2 400 s from here
  for (int k = 1; k <= 480; ++k) {
    f.predict(l);
    if (k % 120 != 0) continue;
    const double a_k = std::exp(-k * l.dt_s / 2400.0);
    EXPECT_NEAR(f.disturbance_W()[1], a_k * d0, 1e-12 * d0) << "step " << k;
    const double p_k = a_k * a_k * p0 + sigma2[1] * (1.0 - a_k * a_k);
    EXPECT_NEAR(f.covariance()(kMaxThermalNodes + 1, kMaxThermalNodes + 1), p_k, 1e-12 * p_k) << "step " << k;
  }
}

TEST(ThermalFilter, GaussMarkovSamplesHaveTheStationaryVarianceAndAutocorrelation) {
  // The discretised process itself, d⁺ = a·d + v with the filter's a and Var(v) (read off one unobserved step
  // from d = 0, P_dd = 0): sampled from its stationary law, its variance is σ_d² and its autocorrelation at lag
  // kΔt is e^{−kΔt/τ_d}. N = 200 000 samples at τ_d/Δt = 20 (a = 0.951): the AR(1) estimates' standard errors are
  // σ²·√(2·(1+a²)/((1−a²)·N)) = 0.014·σ² for the variance and at most √((1+a²)/((1−a²)·N)) = 0.010 for a lag's
  // correlation (Bartlett); asserted at 5 of them.
  ThermalFilterConfig c = two_nodes();
  c.disturbance_W2_per_s << 0.0, 2.0, 0.0, 0.0;
  c.disturbance_time_constant_s << 1.0, 200.0, 1.0, 1.0;
  const double dt = 10.0, tau = 200.0, sigma2 = 2.0 * tau / 2.0;
  ThermalFilter f(c);
  f.set_temperatures(ThermalVec::Constant(25.0), ThermalMat::Zero());
  ThermalLoad l;
  l.dt_s = dt;
  l.coolant_C = 25.0;
  f.predict(l);
  const double var_v = f.covariance()(kMaxThermalNodes + 1, kMaxThermalNodes + 1);
  const double a = std::exp(-dt / tau);
  EXPECT_NEAR(var_v, sigma2 * (1.0 - a * a), 1e-12 * sigma2);
  std::mt19937_64 rng(24);
  std::normal_distribution<double> v(0.0, std::sqrt(var_v));
  const int n = 200000;
  std::vector<double> d(static_cast<std::size_t>(n));
  double x = std::normal_distribution<double>(0.0, std::sqrt(sigma2))(rng);
  for (double& di : d) di = x = a * x + v(rng);
  double s2 = 0.0;
  for (double di : d) s2 += di * di;
  s2 /= n;
  EXPECT_NEAR(s2, sigma2, 5.0 * 0.014 * sigma2);
  for (int lag : {1, 5, 20}) {
    double r = 0.0;
    for (int k = 0; k + lag < n; ++k) r += d[static_cast<std::size_t>(k)] * d[static_cast<std::size_t>(k + lag)];
    r /= (n - lag) * s2;
    EXPECT_NEAR(r, std::exp(-lag * dt / tau), 5.0 * 0.010) << "lag " << lag;
  }
}

TEST(ThermalFilter, GaussMarkovTendsToTheRandomWalk) {
  // τ_d → ∞ (eq. 14.19): a = 1 − Δt/τ_d + …, Var(v) = q_d·Δt·(1 − Δt/τ_d + …); at τ_d = 10¹² s and Δt = 5 s
  // both differ from the walk by 5·10⁻¹², so after 1 000 steps with readings every state and P agree to 1e-8
  // relative (τ_d = +∞ itself is the walk's F and Q_d: the dense test above).
  ThermalFilterConfig walk = two_nodes();
  walk.disturbance_W2_per_s << 10.0, 10.0, 0.0, 0.0;
  walk.process_noise_K2_per_s << 1e-4, 1e-4, 0.0, 0.0;
  ThermalFilterConfig far = walk;
  far.disturbance_time_constant_s.setConstant(1e12);
  ThermalFilter fw(walk), ff(far);
  for (ThermalFilter* f : {&fw, &ff}) f->reset(25.0, 0.5);
  ThermalLoad l;
  l.dt_s = 5.0;
  l.current_sq_A2 = 120.0 * 120.0;
  l.coolant_C = 25.0;
  for (int k = 0; k < 1000; ++k) {
    const double reading = 25.0 + 30.0 * (1.0 - std::exp(-k / 300.0));
    for (ThermalFilter* f : {&fw, &ff}) {
      f->predict(l);
      (void)f->observe(magnet_reading(reading, 0.25));
    }
  }
  ASSERT_GT(fw.disturbance_W().cwiseAbs().maxCoeff(), 10.0);  // a disturbance was learnt
  EXPECT_LT((ff.covariance() - fw.covariance()).cwiseAbs().maxCoeff(), 1e-8 * fw.covariance().cwiseAbs().maxCoeff());
  EXPECT_LT((ff.disturbance_W() - fw.disturbance_W()).cwiseAbs().maxCoeff(),
            1e-8 * fw.disturbance_W().cwiseAbs().maxCoeff());
  EXPECT_LT((ff.temperature_C() - fw.temperature_C()).cwiseAbs().maxCoeff(), 1e-8 * 100.0);
}

TEST(ThermalFilter, BilinearCalibrationTermMeanAndVarianceOverAGaussianPrior) {
  // Eq. 14.10a: for (δT, δe) jointly Gaussian, zero mean, E[δT·δe] = P_Te and Var(δT·δe) = P_TT·P_ee + P_Te²
  // (Isserlis). Checked by sampling, at 5 standard errors, at the Paderborn row 4 480 s's prior (docs/thermal.md,
  // "What the fused worst error is made of": P_TT 90.6 K², P_Te −1.135 K, P_ee 0.01447).
  const double p_tt = 90.607, p_te = -1.1347, p_ee = 0.0144676;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> z;
  const double l11 = std::sqrt(p_tt), l21 = p_te / l11, l22 = std::sqrt(p_ee - l21 * l21);
  const int n = 400000;
  std::vector<double> q(n);
  double sum = 0.0;
  for (double& v : q) {
    const double z1 = z(rng), z2 = z(rng);
    v = (l11 * z1) * (l21 * z1 + l22 * z2);
    sum += v;
  }
  const double mean = sum / n;
  double m2 = 0.0, m4 = 0.0;
  for (const double v : q) m2 += (v - mean) * (v - mean), m4 += std::pow(v - mean, 4);
  m2 /= n, m4 /= n;
  const double var_expected = p_tt * p_ee + p_te * p_te;
  EXPECT_NEAR(mean, p_te, 5.0 * std::sqrt(var_expected / n));
  EXPECT_NEAR(m2, var_expected, 5.0 * std::sqrt((m4 - m2 * m2) / n));  // the sample variance's standard error
}

TEST(ThermalFilter, BilinearCalibrationTermEntersTheInnovationAndItsVariance) {
  // A law reading y = T_m + e_ref + e_α·(T_m − T_ref) (slope 1), readings at T̂ − T_ref = 80 K teach P_Te ≈ −80·σ_α²;
  // then one at 78.5 K. The filter must use ν = y − ŷ − b·P_Te and s = H·P·Hᵀ + r + b²·(P_TT·P_ee + P_Te²)
  // (eq. 14.10a) with K = [P·Hᵀ/s; 0] as before (eq. 14.11). Before 14.10a, s lacked the last term: here it
  // is 2.7 K² against a first-order s of 0.7 K², the gain on T_m exceeded 1/h and the posterior left the
  // interval between prior and reading (Paderborn 4 480 s: −3.47 K for a −1.17 K innovation).
  ThermalFilterConfig c = two_nodes();
  c.calibration_sigma[static_cast<int>(Calibration::kMagnetOffset)] = 1.0;
  c.calibration_sigma[static_cast<int>(Calibration::kMagnetCoefficient)] = 0.12;
  c.gate_sigma = 100.0;
  ThermalFilter f(c);
  f.reset(100.0, 100.0);  // a vague prior: T's error ends almost wholly along the calibration's, as on Paderborn
  const auto reading = [](double value, double d_K) {
    ThermalObservation o = magnet_reading(value, 0.13);
    o.h_c << 1.0, d_K, 0.0, 0.0, 0.0;
    o.bilinear = 1.0;
    o.bilinear_node = 1;
    o.bilinear_state = Calibration::kMagnetCoefficient;
    return o;
  };
  for (int k = 0; k < 200; ++k) ASSERT_EQ(f.observe(reading(100.0, 80.0)), ObservationResult::kAccepted);
  const ThermalStateMat p = f.covariance();
  const int kt = 1, ke = kDynamicThermalStates + static_cast<int>(Calibration::kMagnetCoefficient);
  ASSERT_NEAR(p(kt, ke), -80.0 * 0.12 * 0.12, 0.05);  // the correlation the first readings taught
  const double t0 = f.temperature_C()[kt];
  const ThermalObservation o = reading(98.0, 78.5);
  ThermalStateVec h = ThermalStateVec::Zero();
  h[kt] = 1.0;
  h.tail<kCalibrationStates>() = o.h_c;
  const double second = p(kt, kt) * p(ke, ke) + p(kt, ke) * p(kt, ke);
  const double s = h.dot(p * h) + o.variance + second;
  const double nu = o.value - t0 - p(kt, ke);
  ASSERT_EQ(f.observe(o), ObservationResult::kAccepted);
  EXPECT_NEAR(f.last_innovation_variance(), s, 1e-12 * s);
  EXPECT_NEAR(f.last_innovation(), nu, 1e-12);
  EXPECT_NEAR(f.temperature_C()[kt], t0 + (p * h)[kt] * nu / s, 1e-9);
  // What the first order alone left out (2.67 against 0.18 K²), and its gain on the node, 9.9 > 1/h; now 0.61.
  EXPECT_GT(second, 2.0 * (h.dot(p * h) + o.variance));
  EXPECT_GT((p * h)[kt] / (h.dot(p * h) + o.variance), 1.0);
  EXPECT_NEAR((p * h)[kt] / s, 0.61, 0.01);
}

TEST(ThermalFusion, EachLawsRowCarriesItsBilinearCalibrationTerm) {
  // ψ̂m's row: b = the magnet law's slope ψ_ref·α on the magnet node and its coefficient state; r̂s's likewise.
  ThermalFusionConfig c;
  c.filter = two_nodes();
  c.magnet_law = {-0.0012, 20.0, 0.1169};
  ThermalStepData d;
  for (ParameterObservation& p : d.parameter) p.valid = true, p.variance = 1e-9;
  d.parameter[0].value = 0.106;
  d.parameter[1].value = 0.06;
  const StepObservations o = step_observations(c, d, ThermalVec(110.0, 95.0, 0.0, 0.0), ThermalVec::Zero());
  ASSERT_TRUE(o.present[0] && o.present[1]);
  EXPECT_DOUBLE_EQ(o.item[0].bilinear, 0.1169 * -0.0012);
  EXPECT_EQ(o.item[0].bilinear_node, c.filter.network.magnet);
  EXPECT_EQ(o.item[0].bilinear_state, Calibration::kMagnetCoefficient);
  EXPECT_DOUBLE_EQ(o.item[1].bilinear, 0.05 * 0.00393);
  EXPECT_EQ(o.item[1].bilinear_node, c.filter.network.winding);
  EXPECT_EQ(o.item[1].bilinear_state, Calibration::kCopperCoefficient);
}

}  // namespace
}  // namespace rpem::core
