// Gain algorithms against their equations (eq:SGA_full, eq:GNA_full…eq:GNA_GainElements,
// eq:PhyInterPRet*) and against independent computations.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "rpem/core/gain.hpp"
#include "support/paper_machine.hpp"
#include "support/seed.hpp"

namespace rpem::core {
namespace {

GainFloors no_floors() { return GainFloors{}; }

TEST(Sga, HessianFilterAndGainFollowEqSgaFull) {
  Mat2 g;
  g << -1.5, -1.9, -0.2, 0.3;  // columns ψ̂m, r̂s
  Vec2 r(1.0, 2.0);
  const Vec2 gr(0.1, 0.01), gl(0.05, 0.002);
  const GainOutput out = sga_gain(g, gr, gl, no_floors(), r);
  const double tr = 1.5 * 1.5 + 1.9 * 1.9 + 0.2 * 0.2 + 0.3 * 0.3;
  EXPECT_NEAR(r[0], 1.0 + 0.1 * (tr - 1.0), 1e-15);
  EXPECT_NEAR(r[1], 2.0 + 0.01 * (tr - 2.0), 1e-15);
  EXPECT_NEAR(out.gain(kPsiM, 0), 0.05 / r[0] * -1.5, 1e-15);
  EXPECT_NEAR(out.gain(kPsiM, 1), 0.05 / r[0] * -0.2, 1e-15);
  EXPECT_NEAR(out.gain(kRs, 0), 0.002 / r[1] * -1.9, 1e-15);
  EXPECT_NEAR(out.gain(kRs, 1), 0.002 / r[1] * 0.3, 1e-15);
  EXPECT_EQ(out.flags, 0);
}

TEST(Sga, FloorBoundsTheGainWhereTheGradientVanishes) {
  Vec2 r(0.0, 0.0);
  GainFloors f;
  f.sga_hessian_min_pu = 0.5;
  Mat2 g;
  g << 1e-3, 0.0, 0.0, 0.0;
  const GainOutput out = sga_gain(g, Vec2(0.0, 0.0), Vec2(1.0, 1.0), f, r);
  EXPECT_NEAR(out.gain(kPsiM, 0), 1e-3 / 0.5, 1e-15);
  EXPECT_TRUE(out.flags & gain_flag::kFloored);
}

TEST(Gna, SteadyStateGainIsGammaTimesInverseTransposeAndMatchesPrintedElements) {
  Mat2 g;
  g << -1.52, -1.87, -0.18, 0.25;
  const Mat2 psi = g.transpose();
  Mat2 hessian = psi * psi.transpose();  // R in steady state
  const Vec2 gamma(3.25e-4, 7.5e-6);
  GainFloors f;
  f.gna_determinant_min_pu = 1e-12;
  const GainOutput out = gna_gain(g, 1e-3, gamma, f, hessian);
  // R⁻¹Ψ = Ψ⁻ᵀ when Ψ is square and invertible.
  const Mat2 expected = gamma.asDiagonal() * psi.transpose().inverse();
  EXPECT_LT((out.gain - expected).norm(), 1e-12 * expected.norm());
  // eq:GNA_GainElements, element by element, and eq:InverseR's |R| = (Ψ11Ψ22 − Ψ12Ψ21)².
  const double p11 = psi(0, 0), p12 = psi(0, 1), p21 = psi(1, 0), p22 = psi(1, 1);
  const double det = p11 * p11 * p22 * p22 + p12 * p12 * p21 * p21 - 2.0 * p11 * p12 * p21 * p22;
  EXPECT_NEAR(det, hessian.determinant(), 1e-12);
  const Mat2& R = hessian;
  EXPECT_NEAR(out.gain(0, 0), gamma[0] / det * (p11 * R(1, 1) - p21 * R(0, 1)), 1e-12);
  EXPECT_NEAR(out.gain(0, 1), gamma[0] / det * (p12 * R(1, 1) - p22 * R(0, 1)), 1e-12);
  EXPECT_NEAR(out.gain(1, 0), gamma[1] / det * (p21 * R(0, 0) - p11 * R(0, 1)), 1e-12);
  EXPECT_NEAR(out.gain(1, 1), gamma[1] / det * (p22 * R(0, 0) - p12 * R(0, 1)), 1e-12);
}

TEST(Gna, HessianFilterIsAConvexCombinationThatStaysPositiveSemiDefinite) {
  std::mt19937_64 rng(test::test_seed(5));
  std::normal_distribution<double> nd;
  std::uniform_real_distribution<double> gamma(0.0, 1.0);
  Mat2 R = Mat2::Identity();
  for (int k = 0; k < 10000; ++k) {
    Mat2 g;
    g << nd(rng), nd(rng), nd(rng), nd(rng);
    const Mat2 before = R;
    const double gr = gamma(rng) * gamma(rng);
    (void)gna_gain(g, gr, Vec2::Zero(), no_floors(), R);
    EXPECT_LT((R - (before + gr * (g.transpose() * g - before))).norm(), 1e-12);
    EXPECT_GE(R(0, 0), 0.0);
    EXPECT_GE(det2(R), -1e-12 * R.squaredNorm());
  }
}

TEST(Gna, UsesPseudoInverseBelowTheDeterminantFloorAndStillAdaptsRsAtStandstill) {
  // At standstill Ψ's ψ̂m column is zero: R is singular. The Moore–Penrose inverse keeps the r̂s row
  // alive, where the plain inverse of eq:InverseR would give 0/0 (Section III-D).
  const MachinePu m = test::paper_machine_pu();
  const Vec2 i(-0.02, 0.36);
  const Mat2 g = steady_state_gradients(m, 0.0, i);
  Mat2 R = g.transpose() * g;
  GainFloors f;
  f.gna_determinant_min_pu = 1e-6;
  f.gna_eigenvalue_min_pu = 1e-9;
  const Vec2 gamma(3.25e-4, 7.5e-6);
  const GainOutput out = gna_gain(g, 0.0, gamma, f, R);
  EXPECT_TRUE(out.flags & gain_flag::kPseudoInverse);
  EXPECT_EQ(out.gain.row(kPsiM).norm(), 0.0);
  // With ε = Ψᵀ·δθ (δψ = 0) the update is exactly γ·δr̂s.
  const double drs = -0.004;
  const Vec2 eps = g.col(kRs) * drs;
  EXPECT_NEAR((out.gain * eps)[kRs], gamma[kRs] * drs, 1e-15);
}

// A steady-state sample (a window) on which only ψ̂m adapts (docs/derivations.md §5, "One parameter of a steady-state
// sample"). At i_d = 0 both columns of Ψᵀ are along Z⁻¹·e_q, in the ratio n : i_q, so R of a window at n₁ and this one at
// n₂ (the drive accelerating) is full rank but nearly singular, and the joint step's ψ̂m row contracts δψ̂m by exactly
// a = (γ_L/γ_r)·n₂/(n₂ − n₁) — 23 for a 2.5 % change of speed: ψ̂m thrown far past the value. ψ̂m's own Newton step,
// L_ψ = γ_L·Ψ_ψ/R_ψψ, contracts by γ_L·|Ψ_ψ|²/R_ψψ ∈ [0, γ_L/γ_r], whatever R holds.
TEST(Gna, AWindowOnWhichOneParameterAdaptsTakesItsOwnNewtonStep) {
  const MachinePu m{0.05, 0.1, 0.1, 1.0};  // a surface-magnet machine, pu
  const Vec2 i(0.0, 0.5);
  const double n1 = 0.40, n2 = 0.41, gamma_r = 0.3;
  const Vec2 gamma_l(0.17, 0.02);
  const Mat2 g1 = steady_state_gradients(m, n1, i), g2 = steady_state_gradients(m, n2, i);
  const auto contraction = [&](const GainOutput& out) { return out.gain.row(kPsiM).dot(g2.col(kPsiM)); };

  Mat2 joint_r = g1.transpose() * g1;
  const GainOutput joint = gna_gain(g2, gamma_r, gamma_l, no_floors(), joint_r);
  const double a_joint = contraction(joint);  // the row eq:GainSchedule keeps
  EXPECT_NEAR(a_joint, gamma_l[kPsiM] / gamma_r * n2 / (n2 - n1), 1e-6 * std::abs(a_joint));
  EXPECT_GT(a_joint, 2.0);  // |1 − a| > 1: the masked step diverges

  Mat2 own_r = g1.transpose() * g1;
  const GainOutput own = gna_gain(g2, gamma_r, gamma_l, no_floors(), own_r, kPsiM);
  EXPECT_EQ(own_r, joint_r);           // the same R: only the step differs
  const Vec2 psi_row = g2.col(kPsiM);  // Ψ_ψ: dî/dψ̂m
  EXPECT_LT((own.gain.row(kPsiM).transpose() - gamma_l[kPsiM] / own_r(kPsiM, kPsiM) * psi_row).norm(),
            1e-15 * psi_row.norm());
  EXPECT_EQ(own.gain.row(kRs).norm(), 0.0);
  EXPECT_EQ(own.flags, 0);
  const double a_own = contraction(own);
  EXPECT_GE(a_own, 0.0);
  EXPECT_LE(a_own, gamma_l[kPsiM] / gamma_r);
  // The same for r̂s alone; and an R_jj at the eigenvalue floor takes no step, flagged as R⁺.
  Mat2 rs_r = g1.transpose() * g1;
  const GainOutput rs = gna_gain(g2, gamma_r, gamma_l, no_floors(), rs_r, kRs);
  EXPECT_NEAR(rs.gain(kRs, 1), gamma_l[kRs] / rs_r(kRs, kRs) * g2(1, kRs), 1e-15);
  EXPECT_EQ(rs.gain.row(kPsiM).norm(), 0.0);
  GainFloors floors;
  floors.gna_eigenvalue_min_pu = 1e3;
  Mat2 floored_r = g1.transpose() * g1;
  const GainOutput floored = gna_gain(g2, gamma_r, gamma_l, floors, floored_r, kPsiM);
  EXPECT_EQ(floored.gain.norm(), 0.0);
  EXPECT_TRUE(floored.flags & gain_flag::kPseudoInverse);
}

TEST(PseudoInverse, SatisfiesThePenroseConditionsOnRandomSymmetricMatrices) {
  std::mt19937_64 rng(test::test_seed(2024));
  std::normal_distribution<double> nd;
  for (int k = 0; k < 2000; ++k) {
    Vec2 a(nd(rng), nd(rng)), b(nd(rng), nd(rng));
    Mat2 r = a * a.transpose();
    if (k % 3 == 0) r += b * b.transpose();  // full rank
    if (k % 7 == 0) r.setZero();
    const Mat2 p = symmetric_pseudo_inverse(r, 1e-12);
    const double scale = std::max(1.0, r.norm()) * std::max(1.0, p.norm());
    EXPECT_LT((r * p * r - r).norm(), 1e-10 * scale) << k;
    EXPECT_LT((p * r * p - p).norm(), 1e-10 * scale * p.norm() + 1e-12) << k;
    EXPECT_LT(((r * p).transpose() - r * p).norm(), 1e-10 * scale) << k;
    EXPECT_LT(((p * r).transpose() - p * r).norm(), 1e-10 * scale) << k;
    if (k % 3 == 0 && k % 7 != 0 && std::abs(r.determinant()) > 1e-6) {
      EXPECT_LT((p - r.inverse()).norm(), 1e-8 * r.inverse().norm()) << k;
    }
  }
}

TEST(PhyInt, PsiGainIsMinusGammaXd) {
  const MachinePu m = test::paper_machine_pu();
  GainFloors f;
  const GainOutput out = phyint_gain(m, 0.8, Vec2(-0.1, 0.4), Vec2(3.25e-4, 0.0), f);
  EXPECT_DOUBLE_EQ(out.gain(kPsiM, 0), -3.25e-4 * m.x_d_pu);
  EXPECT_EQ(out.gain(kPsiM, 1), 0.0);
}

TEST(PhyInt, RsUpdateRecoversGammaTimesTheResistanceError) {
  // ε from eq_epsilon_steadystate (δψ = 0) with î = i: L·ε = γ·δr̂s (the 1/m weight, erratum E3).
  const MachinePu m = test::paper_machine_pu();
  const double drs = 0.0035, gamma = 6.25e-5;
  GainFloors f;
  f.phyint_denominator_min_pu = 1e-4;
  for (double n : {0.0, 0.005, -0.05}) {
    const Vec2 i(-0.15, 0.5);
    const Mat2 g = steady_state_gradients(m, n, i);
    const Vec2 eps = g.col(kRs) * drs;
    const GainOutput out = phyint_gain(m, n, i, Vec2(0.0, gamma), f);
    EXPECT_NEAR((out.gain * eps)[kRs], gamma * drs, 1e-15) << "n=" << n;
  }
}

TEST(PhyInt, ComponentBelowTheFloorIsLeftOut) {
  const MachinePu m = test::paper_machine_pu();
  GainFloors f;
  f.phyint_denominator_min_pu = 1e-3;
  // Standstill, i_d = 0: den_d = 0, only the q component is used, with full weight.
  const Vec2 i(0.0, 0.4);
  const GainOutput out = phyint_gain(m, 0.0, i, Vec2(0.0, 1.0), f);
  EXPECT_TRUE(out.flags & gain_flag::kFloored);
  EXPECT_EQ(out.gain(kRs, 0), 0.0);
  EXPECT_NEAR(out.gain(kRs, 1), m.r_s_pu * m.r_s_pu / (-m.r_s_pu * 0.4), 1e-15);
  // No current at all: no r̂s information, no gain.
  const GainOutput none = phyint_gain(m, 0.0, Vec2::Zero(), Vec2(0.0, 1.0), f);
  EXPECT_EQ(none.gain.row(kRs).norm(), 0.0);
}

}  // namespace
}  // namespace rpem::core
