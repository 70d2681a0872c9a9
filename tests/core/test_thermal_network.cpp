// The thermal network (core/thermal_network.hpp, docs/derivations.md §13) against closed forms and an
// independent integrator: the matrix exponential and φ₁, one node's exponential approach with the copper
// loss's own temperature law, two coupled nodes against their 2×2 exponential in closed form, a coupled network
// stepped exactly against fine RK4, the loss forms' bases.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/LU>

#include "rpem/core/matrix_exponential.hpp"
#include "rpem/core/thermal_network.hpp"
#include "rpem/core/thermal_stability.hpp"

namespace rpem::core {
namespace {

using Mat3 = Eigen::Matrix<double, 3, 3>;

TEST(MatrixExponential, MatchesClosedFormsAcrossNorms) {
  // Diagonal: e^d per element, from tiny to large norms (many squarings).
  for (double scale : {1e-6, 0.3, 7.0, 60.0}) {
    const Mat3 d = Eigen::Vector3d(-1.0, 0.5, -2.0).asDiagonal() * scale;
    const ExponentialPair<3> e = exponential_and_phi1<3>(d);
    for (int k = 0; k < 3; ++k) {
      const double x = d(k, k);
      EXPECT_NEAR(e.exp(k, k) / std::exp(x), 1.0, 1e-12) << scale;
      EXPECT_NEAR(e.phi1(k, k) / (std::expm1(x) / x), 1.0, 1e-12) << scale;  // φ₁(x) = (e^x − 1)/x
    }
  }
  // A rotation generator: e^{[0 −w; w 0]} is the rotation by w.
  Eigen::Matrix2d j;
  j << 0.0, -2.3, 2.3, 0.0;
  const Eigen::Matrix2d r = matrix_exponential<2>(j);
  EXPECT_NEAR(r(0, 0), std::cos(2.3), 1e-13);
  EXPECT_NEAR(r(1, 0), std::sin(2.3), 1e-13);
  // Nilpotent: e^N = I + N + N²/2 exactly.
  Mat3 n = Mat3::Zero();
  n(0, 1) = 4.0, n(1, 2) = -3.0, n(0, 2) = 0.5;
  const Mat3 exact = Mat3::Identity() + n + 0.5 * n * n;
  EXPECT_LT((matrix_exponential<3>(n) - exact).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(MatrixExponential, Phi1IsTheIntegralOfTheExponential) {
  // Δt·φ₁(A·Δt) = A⁻¹·(e^{A·Δt} − I) for an invertible A, here a stiff non-symmetric one.
  Mat3 a;
  a << -2.0, 0.3, 0.0, 0.1, -0.05, 0.02, 0.0, 1.5, -40.0;
  for (double dt : {0.01, 1.0, 25.0}) {
    const ExponentialPair<3> e = exponential_and_phi1<3>(a * dt);
    const Mat3 integral = a.inverse() * (e.exp - Mat3::Identity());
    EXPECT_LT((dt * e.phi1 - integral).cwiseAbs().maxCoeff(), 1e-10 * integral.cwiseAbs().maxCoeff()) << dt;
  }
}

/// A two-node network whose magnet is decoupled from the winding: the winding alone is one node.
ThermalNetwork decoupled() {
  ThermalNetwork n;
  n.nodes = 2;
  n.capacitance_J_per_K << 4000.0, 9000.0, 1.0, 1.0;
  n.to_coolant_W_per_K << 25.0, 6.0, 0.0, 0.0;
  n.copper = {0.00393, 20.0, 0.05};
  n.base = {1000.0, 0.1, 100.0};
  n.loss_at_base_W(static_cast<int>(LossForm::kIronEddy), 0) = 80.0;
  n.loss_at_base_W(static_cast<int>(LossForm::kMagnetEddy), 1) = 30.0;
  return n;
}

TEST(ThermalNetwork, OneNodeApproachesItsSteadyStateExponentiallyWithTheCopperLaw) {
  // C·dT/dt = (3/2)·R_ref·(1 + α(T − T_ref))·i² + k·b − G·(T − T_c): first order with G_eff = G − (3/2)·R_ref·α·i².
  const ThermalNetwork n = decoupled();
  ThermalLoad l;
  l.dt_s = 37.0;
  l.current_sq_A2 = 150.0 * 150.0;
  l.coolant_C = 25.0;
  l.basis = loss_basis(n.base, Vec2(-90.0, 120.0), 800.0, Vec2(0.07, 0.05));
  const double i2 = l.current_sq_A2, r = n.copper.value_ref, alpha = n.copper.coeff_per_K;
  const double g_eff = 25.0 - 1.5 * r * alpha * i2;
  const double p0 = 1.5 * r * (1.0 - alpha * 20.0) * i2 + 80.0 * l.basis[static_cast<std::size_t>(LossForm::kIronEddy)];
  const double t_inf = (25.0 * 25.0 + p0) / g_eff;
  const double tau = 4000.0 / g_eff;
  const ThermalVec t0(25.0, 25.0, 0.0, 0.0);
  const ThermalTransition tr = thermal_transition(n, l);
  const ThermalVec t1 = tr.phi * t0 + tr.gamma;
  EXPECT_NEAR(t1[0], t_inf + (25.0 - t_inf) * std::exp(-37.0 / tau), 1e-9);
  EXPECT_NEAR(thermal_steady_state(n, l)[0], t_inf, 1e-9);
  // The magnet: its own loss through its own conductance.
  const double m_inf = 25.0 + 30.0 * l.basis[static_cast<std::size_t>(LossForm::kMagnetEddy)] / 6.0;
  EXPECT_NEAR(t1[1], m_inf + (25.0 - m_inf) * std::exp(-37.0 * 6.0 / 9000.0), 1e-9);
  // Unused nodes keep their value and take no heat.
  EXPECT_EQ(tr.phi(2, 2), 1.0);
  EXPECT_EQ(tr.gamma[3], 0.0);
  EXPECT_EQ(tr.gamma_d.col(3).norm(), 0.0);
}

TEST(ThermalNetwork, TwoCoupledNodesStepAsTheirTwoByTwoExponentialInClosedForm) {
  // A 2-node network's step comes from the series on its 2×2 block (core/src/thermal_network.cpp). Here the
  // block in closed form: A's eigenvalues λ₁ ≠ λ₂ (real and negative for a network with a path to the coolant),
  // e^{AΔt} = (λ₁·e^{λ₂Δt} − λ₂·e^{λ₁Δt})/(λ₁ − λ₂)·I + (e^{λ₁Δt} − e^{λ₂Δt})/(λ₁ − λ₂)·A (Putzer), and the
  // step's input ∫₀^Δt e^{As} ds·u = A⁻¹·(e^{AΔt} − I)·u.
  ThermalNetwork n = decoupled();
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 15.0;
  n.between_at_base_speed_W_per_K(0, 1) = n.between_at_base_speed_W_per_K(1, 0) = 4.0;
  ThermalLoad l;
  l.dt_s = 90.0;
  l.current_sq_A2 = 120.0 * 120.0;
  l.coolant_C = 35.0;
  l.convection_basis = 0.6;
  l.basis = loss_basis(n.base, Vec2(-70.0, 110.0), 700.0, Vec2(0.06, 0.05));
  const ThermalRates rates = thermal_rates(n, l);
  const Eigen::Matrix2d a = rates.a.topLeftCorner<2, 2>();
  const Eigen::Vector2d u = rates.u.head<2>();
  const double mean = 0.5 * a.trace(),
               half_gap = std::sqrt(0.25 * (a(0, 0) - a(1, 1)) * (a(0, 0) - a(1, 1)) + a(0, 1) * a(1, 0));
  const double l1 = mean + half_gap, l2 = mean - half_gap, e1 = std::exp(l1 * l.dt_s), e2 = std::exp(l2 * l.dt_s);
  ASSERT_LT(l1, 0.0);
  const Eigen::Matrix2d phi = (l1 * e2 - l2 * e1) / (l1 - l2) * Eigen::Matrix2d::Identity() + (e1 - e2) / (l1 - l2) * a;
  const Eigen::Vector2d gamma = a.inverse() * (phi - Eigen::Matrix2d::Identity()) * u;
  const ThermalTransition tr = thermal_transition(n, l);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(tr.gamma[i], gamma[i], 1e-12 * gamma.norm()) << i;
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(tr.phi(i, j), phi(i, j), 1e-14) << i << j;
  }
  // The unused block is the identity and takes no heat; nothing couples it to the nodes in use.
  EXPECT_TRUE(tr.phi.bottomRightCorner(2, 2).isIdentity(0.0));
  EXPECT_EQ(tr.phi.topRightCorner(2, 2).norm() + tr.phi.bottomLeftCorner(2, 2).norm(), 0.0);
  EXPECT_EQ(tr.gamma.tail<2>().norm(), 0.0);
  // The same network as four nodes of which two are unused rows: the 4×4 series gives the same step.
  const ExponentialPair<kMaxThermalNodes> full = exponential_and_phi1<kMaxThermalNodes>(rates.a * l.dt_s);
  EXPECT_LT((full.exp - tr.phi).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ThermalNetwork, ExactStepMatchesFineRungeKuttaOnACoupledNetwork) {
  ThermalNetwork n;
  n.nodes = 3;
  n.winding = 0, n.magnet = 2;
  n.capacitance_J_per_K << 3000.0, 12000.0, 7000.0, 1.0;
  n.to_coolant_W_per_K << 2.0, 90.0, 4.0, 0.0;
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 40.0;
  n.between_W_per_K(1, 2) = n.between_W_per_K(2, 1) = 12.0;
  n.copper = {0.0039, 20.0, 0.03};
  n.base = {2000.0, 0.08, 150.0};
  n.loss_at_base_W(static_cast<int>(LossForm::kIronHysteresis), 1) = 300.0;
  n.loss_at_base_W(static_cast<int>(LossForm::kIronEddy), 2) = 60.0;
  ThermalLoad l;
  l.dt_s = 120.0;
  l.current_sq_A2 = 180.0 * 180.0;
  l.coolant_C = 40.0;
  l.basis = loss_basis(n.base, Vec2(-120.0, 130.0), 1500.0, Vec2(0.05, 0.06));
  const ThermalVec d(5.0, 0.0, -20.0, 0.0);  // a held heat disturbance [W]
  ThermalVec t(60.0, 45.0, 70.0, 0.0);
  // RK4 on C·dT/dt written out from eq. 13.1–13.3 (not through thermal_rates), 12 000 steps.
  auto rhs = [&](const ThermalVec& x) {
    const double r_s = n.copper.at(x[0]);
    ThermalVec p = ThermalVec::Zero();
    p[0] = 1.5 * r_s * l.current_sq_A2;
    p[1] = 300.0 * l.basis[0];
    p[2] = 60.0 * l.basis[1];
    ThermalVec dx = ThermalVec::Zero();
    dx[0] = (p[0] + d[0] - 2.0 * (x[0] - 40.0) - 40.0 * (x[0] - x[1])) / 3000.0;
    dx[1] = (p[1] + d[1] - 90.0 * (x[1] - 40.0) - 40.0 * (x[1] - x[0]) - 12.0 * (x[1] - x[2])) / 12000.0;
    dx[2] = (p[2] + d[2] - 4.0 * (x[2] - 40.0) - 12.0 * (x[2] - x[1])) / 7000.0;
    return dx;
  };
  ThermalVec x = t;
  const int steps = 12000;
  const double h = l.dt_s / steps;
  for (int k = 0; k < steps; ++k) {
    const ThermalVec k1 = rhs(x), k2 = rhs(x + 0.5 * h * k1), k3 = rhs(x + 0.5 * h * k2), k4 = rhs(x + h * k3);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  const ThermalTransition tr = thermal_transition(n, l);
  const ThermalVec exact = tr.phi * t + tr.gamma + tr.gamma_d * d;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(exact[i], x[i], 1e-9) << i;
}

TEST(LossForms, BasesAreOneAtTheBaseAndScaleAsDerived) {
  const LossBase base{1000.0, 0.1, 50.0};
  // At the base: each form's basis is 1.
  const auto at_base = loss_basis(base, Vec2(0.0, 50.0), 1000.0, Vec2(0.1, 0.0));
  for (double b : at_base) EXPECT_NEAR(b, 1.0, 1e-15);
  // Half the frequency, 0.8 of the flux, 1.5 of the current: f·ψ², f²·ψ², f²·i².
  const auto b = loss_basis(base, Vec2(-45.0, 60.0), -500.0, Vec2(0.048, 0.064));
  EXPECT_NEAR(b[static_cast<std::size_t>(LossForm::kIronHysteresis)], 0.5 * 0.64, 1e-15);
  EXPECT_NEAR(b[static_cast<std::size_t>(LossForm::kIronEddy)], 0.25 * 0.64, 1e-15);
  EXPECT_NEAR(b[static_cast<std::size_t>(LossForm::kMagnetEddy)], 0.25 * 2.25, 1e-15);
}

TEST(LossAccumulator, GivesTimeWeightedMeansAndStartsOver) {
  const LossBase base{1000.0, 0.1, 50.0};
  LossAccumulator acc;
  acc.add(base, 1.0, Vec2(10.0, 0.0), 1000.0, Vec2(0.1, 0.0), 20.0);
  acc.add(base, 3.0, Vec2(0.0, 20.0), 500.0, Vec2(0.1, 0.0), 40.0);
  const ThermalLoad l = acc.take();
  EXPECT_DOUBLE_EQ(l.dt_s, 4.0);
  EXPECT_DOUBLE_EQ(l.current_sq_A2, (100.0 + 3.0 * 400.0) / 4.0);  // the mean of i², not the square of the mean
  EXPECT_DOUBLE_EQ(l.coolant_C, 35.0);
  EXPECT_DOUBLE_EQ(l.basis[static_cast<std::size_t>(LossForm::kIronHysteresis)], (1.0 + 3.0 * 0.5) / 4.0);
  EXPECT_DOUBLE_EQ(l.convection_basis, (1.0 + 3.0 * std::sqrt(0.5)) / 4.0);  // eq. 14.1b: the mean of √(|ω|/ω_b)
  EXPECT_EQ(acc.duration_s(), 0.0);
}

TEST(ThermalNetwork, SpeedPartOfTheCoolantConductanceGrowsAsTheSquareRootOfSpeed) {
  // eq. 14.1b: G_m0(ω) = G_m0 + G_m0,ω·√(|ω|/ω_b). The magnet of decoupled() is one node heated by its own
  // loss: T_∞ = T_c + P/G_m0(ω), τ = C/G_m0(ω) — at standstill the static part alone, at a quarter of the base
  // speed (√ = 1/2) half the speed part more, through the same load's accumulated mean.
  ThermalNetwork n = decoupled();
  n.to_coolant_at_base_speed_W_per_K[1] = 10.0;
  for (const double omega : {0.0, -250.0}) {
    LossAccumulator acc;
    acc.add(n.base, 2.0, Vec2(0.0, 100.0), omega, Vec2(0.1, 0.0), 30.0);
    const ThermalLoad l = acc.take();
    const double g = 6.0 + 10.0 * std::sqrt(std::abs(omega) / 1000.0);
    const double p = 30.0 * l.basis[static_cast<std::size_t>(LossForm::kMagnetEddy)];
    EXPECT_NEAR(thermal_steady_state(n, l)[1], 30.0 + p / g, 1e-9) << omega;
    const ThermalRates r = thermal_rates(n, l);
    EXPECT_NEAR(r.a(1, 1), -g / 9000.0, 1e-15) << omega;
    EXPECT_NEAR(r.u[1], (p + g * 30.0) / 9000.0, 1e-12) << omega;
  }
  // The winding has no speed part: its conductance is the same at every speed.
  ThermalLoad still, fast;
  fast.convection_basis = 1.0;
  EXPECT_EQ(thermal_rates(n, still).a(0, 0), thermal_rates(n, fast).a(0, 0));
  // Across the air gap (between two nodes): G_wm(ω) = G_wm + G_wm,ω·√(|ω|/ω_b), symmetric, in both rows.
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 3.0;
  n.between_at_base_speed_W_per_K(0, 1) = n.between_at_base_speed_W_per_K(1, 0) = 8.0;
  ThermalLoad gap;
  gap.convection_basis = 0.75;
  const ThermalRates r = thermal_rates(n, gap);
  const double g_gap = 3.0 + 8.0 * 0.75;
  EXPECT_NEAR(r.a(0, 1), g_gap / 4000.0, 1e-15);
  EXPECT_NEAR(r.a(1, 0), g_gap / 9000.0, 1e-15);
  EXPECT_NEAR(r.a(0, 0), -(25.0 + g_gap) / 4000.0, 1e-15);
  EXPECT_NEAR(r.a(1, 1), -(6.0 + 10.0 * 0.75 + g_gap) / 9000.0, 1e-15);
}

TEST(ThermalNetwork, SettlesExactlyWhileTheCopperLossRisesSlowerThanTheWindingConducts) {
  // eq. 14.27 on two nodes: −C·A = [[G_w0 + G_wm − K, −G_wm], [−G_wm, G_m0(ω) + G_wm]] is positive definite iff
  // K < K* = G_w0 + G_wm·G_m0(ω)/(G_wm + G_m0(ω)): the winding's conductance to the coolant, directly and in
  // series through the magnet. K = s_cu·(3/2)·R_ref·α·|i|², so the current at which the winding runs away is
  // |i|*² = K*/(s_cu·(3/2)·R_ref·α); the check must turn there, at standstill and with the speed part.
  ThermalNetwork n = decoupled();
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 3.0;
  n.to_coolant_at_base_speed_W_per_K[1] = 10.0;
  n.copper_scale = 1.3;
  for (const double basis : {0.0, 0.6}) {
    const double g_m0 = 6.0 + 10.0 * basis;
    const double k_star = 25.0 + 3.0 * g_m0 / (3.0 + g_m0);
    const double i2_star = k_star / (1.3 * 1.5 * n.copper.value_ref * n.copper.coeff_per_K);
    ThermalLoad l;
    l.convection_basis = basis;
    for (const double ratio : {0.0, 0.5, 0.999}) {
      l.current_sq_A2 = ratio * i2_star;
      EXPECT_TRUE(thermal_settles(n, l)) << basis << " " << ratio;
    }
    l.current_sq_A2 = 1.001 * i2_star;
    EXPECT_FALSE(thermal_settles(n, l)) << basis;
    // Below K*, the steady state holds: a step long against every time constant lands on it.
    l.current_sq_A2 = 0.9 * i2_star;
    l.dt_s = 1e7;
    const ThermalTransition tr = thermal_transition(n, l);
    const ThermalVec t = tr.phi * ThermalVec(25.0, 25.0, 0.0, 0.0) + tr.gamma;
    EXPECT_NEAR(t[0], thermal_steady_state(n, l)[0], 1e-6 * std::abs(t[0])) << basis;
  }
  // No path to the coolant at all: the Laplacian alone is singular, so nothing settles even without current.
  ThermalNetwork closed = n;
  closed.to_coolant_W_per_K.setZero();
  closed.to_coolant_at_base_speed_W_per_K.setZero();
  EXPECT_FALSE(thermal_settles(closed, ThermalLoad{}));
}

}  // namespace
}  // namespace rpem::core
