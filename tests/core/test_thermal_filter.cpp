// The thermal Kalman filter (core/thermal_filter.hpp, docs/derivations.md §14) against hand-worked updates
// and closed-form limits: the scalar update, a correlated update, Schmidt's consider states (the calibration
// bounds what observations can teach), the gate, the prediction's covariance, and a heat disturbance the
// filter learns from observations of one node; the blockwise prediction and sparse update against the dense
// forms on all twelve states; a law's bilinear calibration term taken over the prior (eq. 14.10a).
#include <gtest/gtest.h>

#include <cmath>
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

TEST(ThermalFilter, BlockwiseStepsAreTheDenseFormulasAndKeepPExactlySymmetric) {
  // The filter predicts blockwise and updates with a sparse H (docs/derivations.md §14, eq. 14.11, 14.12);
  // here the dense forms on all 12 states: P⁺ = F·P·Fᵀ + Q_d with F = [Φ Γ_d 0; 0 I 0; 0 0 I], and the Joseph
  // form (I − K·H)·P·(I − K·H)ᵀ + K·r·Kᵀ with K = [P·Hᵀ/s on T and d; 0 on c]. Four nodes in use, so every row
  // of the network moves, with a disturbance and cross-covariances built by earlier steps.
  ThermalFilterConfig c;
  ThermalNetwork& n = c.network;
  n.nodes = 4;
  n.winding = 0, n.magnet = 3;
  n.capacitance_J_per_K << 3000.0, 12000.0, 5000.0, 7000.0;
  n.to_coolant_W_per_K << 2.0, 90.0, 10.0, 4.0;
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
  ThermalFilter f(c);
  f.reset(40.0, 5.0);
  ThermalLoad l;
  l.dt_s = 7.0;
  l.current_sq_A2 = 900.0;
  l.basis[static_cast<std::size_t>(LossForm::kIronEddy)] = 0.5;
  l.coolant_C = 30.0;
  ThermalObservation magnet;  // the magnet through a law with its calibration states, and the winding
  magnet.h << 0.1, 0.0, 0.0, -1.4e-3;
  magnet.h_c << -1.4e-3, -0.04, 0.0, 0.0;
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
  ASSERT_GT((p0.block<4, 4>(0, 8).cwiseAbs().maxCoeff()), 0.0);
  EXPECT_TRUE(p0 == p0.transpose());

  f.predict(l);
  const ThermalTransition tr = thermal_transition(n, l);
  ThermalStateMat big_f = ThermalStateMat::Identity();
  big_f.block<4, 4>(0, 0) = tr.phi;
  big_f.block<4, 4>(0, 4) = tr.gamma_d;
  ThermalStateMat q_d = ThermalStateMat::Zero();
  const ThermalMat q_t = c.process_noise_K2_per_s.asDiagonal();
  q_d.block<4, 4>(0, 0) = 0.5 * l.dt_s * (tr.phi * q_t * tr.phi.transpose() + q_t);
  q_d.block<4, 4>(4, 4) = (c.disturbance_W2_per_s * l.dt_s).asDiagonal();
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
  k.tail<4>().setZero();  // Schmidt: the calibration states are considered, not estimated
  const ThermalStateMat i_kh = ThermalStateMat::Identity() - k * h.transpose();
  const ThermalStateMat p2 = i_kh * p1 * i_kh.transpose() + k * magnet.variance * k.transpose();
  const ThermalStateVec x2 = x1 + k * (magnet.value - h.dot(x1) - magnet.offset);
  ASSERT_EQ(f.observe(magnet), ObservationResult::kAccepted);
  EXPECT_NEAR(f.last_innovation_variance(), s, 1e-13 * s);
  EXPECT_LT((f.covariance() - p2).cwiseAbs().maxCoeff(), tol_p);
  EXPECT_LT((state() - x2).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(f.covariance() == f.covariance().transpose());
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
    o.h_c << 1.0, d_K, 0.0, 0.0;
    o.bilinear = 1.0;
    o.bilinear_node = 1;
    o.bilinear_state = Calibration::kMagnetCoefficient;
    return o;
  };
  for (int k = 0; k < 200; ++k) ASSERT_EQ(f.observe(reading(100.0, 80.0)), ObservationResult::kAccepted);
  const ThermalStateMat p = f.covariance();
  const int kt = 1, ke = 8 + static_cast<int>(Calibration::kMagnetCoefficient);
  ASSERT_NEAR(p(kt, ke), -80.0 * 0.12 * 0.12, 0.05);  // the correlation the first readings taught
  const double t0 = f.temperature_C()[kt];
  const ThermalObservation o = reading(98.0, 78.5);
  ThermalStateVec h = ThermalStateVec::Zero();
  h[kt] = 1.0;
  h.tail<4>() = o.h_c;
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
