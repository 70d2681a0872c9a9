// Item 6 of the core issue: the steady-state gradients (docs/derivations.md, erratum E2) equal
// (a) the equilibrium of the discretized dynamic gradients and (b) a central finite difference of the
// discretized predictor's equilibrium, relative error < 1e-6, over the four-quadrant speed-torque plane.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "rpem/core/machine.hpp"
#include "rpem/core/predictor.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

using test::kDt;
using test::kOmegaN;

/// Equilibrium of the discrete predictor under a constant rotor-frame input, found from the map itself:
/// x ↦ F(x) is affine, so three evaluations give Φ and c, and (I − Φ)·x* = c. Also returns the
/// equilibrium of the dynamic gradients the same way.
struct Equilibrium {
  Vec2 i_hat;
  Mat2 gradient;
};

Equilibrium discrete_equilibrium(const MachinePu& model, double n, const Vec2& u) {
  PredictorInterval iv{kDt, n, n, u, u};
  auto step_current = [&](const Vec2& x) {
    PredictorState s;
    s.i_hat_pu = x;
    predict(model, kOmegaN, Discretization::kTrapezoidal, iv, s);
    return s.i_hat_pu;
  };
  const Vec2 c = step_current(Vec2::Zero());
  Mat2 phi;
  phi.col(0) = step_current(Vec2(1.0, 0.0)) - c;
  phi.col(1) = step_current(Vec2(0.0, 1.0)) - c;
  Equilibrium e;
  e.i_hat = (Mat2::Identity() - phi).fullPivLu().solve(c);
  // Gradient map at the current equilibrium: g ↦ G(g), affine in g for each column.
  auto step_gradient = [&](const Mat2& g) {
    PredictorState s;
    s.i_hat_pu = e.i_hat;
    s.gradient = g;
    predict(model, kOmegaN, Discretization::kTrapezoidal, iv, s);
    return s.gradient;
  };
  const Mat2 g0 = step_gradient(Mat2::Zero());
  e.gradient = (Mat2::Identity() - phi).fullPivLu().solve(g0);  // same Φ acts on each column
  return e;
}

double relative_error(const Vec2& a, const Vec2& b) { return (a - b).norm() / std::max(b.norm(), 1e-12); }

class GradientPlane : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(GradientPlane, SteadyStateEqualsDynamicEquilibriumAndFiniteDifference) {
  const auto [n, tau] = GetParam();
  const MachinePu model = test::paper_machine_pu();
  const Vec2 i_op = mtpa_reference(model, tau);
  const Vec2 u = steady_state_voltage(model, n, i_op);

  const Equilibrium eq = discrete_equilibrium(model, n, u);
  // The trapezoidal equilibrium is the continuous one.
  ASSERT_LT((eq.i_hat - i_op).norm(), 1e-9 * std::max(1.0, i_op.norm()));

  const Mat2 analytic = steady_state_gradients(model, n, eq.i_hat);
  EXPECT_LT(relative_error(eq.gradient.col(kPsiM), analytic.col(kPsiM)), 1e-6) << "psi_m n=" << n << " tau=" << tau;
  EXPECT_LT(relative_error(eq.gradient.col(kRs), analytic.col(kRs)), 1e-6) << "r_s n=" << n << " tau=" << tau;

  // Central finite differences of the discrete equilibrium.
  for (int p : {kPsiM, kRs}) {
    const double base = p == kPsiM ? model.psi_m_pu : model.r_s_pu;
    const double h = 1e-5 * base;
    MachinePu plus = model, minus = model;
    (p == kPsiM ? plus.psi_m_pu : plus.r_s_pu) = base + h;
    (p == kPsiM ? minus.psi_m_pu : minus.r_s_pu) = base - h;
    const Vec2 fd = (discrete_equilibrium(plus, n, u).i_hat - discrete_equilibrium(minus, n, u).i_hat) / (2.0 * h);
    if (analytic.col(p).norm() < 1e-9) {
      EXPECT_LT(fd.norm(), 1e-6) << "p=" << p;  // r_s gradient vanishes with the current
    } else {
      EXPECT_LT(relative_error(fd, analytic.col(p)), 1e-6) << "p=" << p << " n=" << n << " tau=" << tau;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(FourQuadrants, GradientPlane,
                         ::testing::Combine(::testing::Values(-2.0, -1.0, -0.4, -0.1, -0.01, 0.0, 0.005, 0.1, 0.4, 1.0, 2.0),
                                            ::testing::Values(-1.0, -0.4, -0.1, 0.0, 0.1, 0.4, 1.0)));

TEST(Gradients, PrintedSteadyStateFormIsWrongWithoutTheSquare) {
  // Erratum E2: eq:PEG_steadySTate_psim prints r̂s + n²x_qx_d. At standstill-near speeds that differs
  // from the dynamic equilibrium by a factor of about 1/r̂s ≈ 21.
  const MachinePu m = test::paper_machine_pu();
  const double n = 0.01;
  const double printed = -n * n * m.x_q_pu / (m.r_s_pu + n * n * m.x_q_pu * m.x_d_pu);
  const double derived = steady_state_gradients(m, n, Vec2::Zero())(0, kPsiM);
  EXPECT_GT(std::abs(derived / printed), 10.0);
}

TEST(Gradients, DeterminantOfPsiIsMinusNTimesIdOverD) {
  // det Ψ = −n·î_d/D (docs/derivations.md): |R| = det(Ψ)² vanishes at standstill and wherever î_d = 0,
  // which is why GNA is over-excited at low load with MTPA (i_d ≈ 0).
  const MachinePu m = test::paper_machine_pu();
  for (double n : {-0.8, -0.2, 0.05, 0.3, 1.0}) {
    for (double id : {-0.5, -0.1, 0.0, 0.2}) {
      const Vec2 i(id, 0.37);
      const Mat2 g = steady_state_gradients(m, n, i);
      EXPECT_NEAR(g.determinant(), -n * id / steady_state_denominator(m, n), 1e-12);
    }
  }
}

/// The ψ̂m at which an algorithm stops moving (r̂s held, as the scheduler holds it at speed) when the plant
/// receives u + e_u while the model is fed u: SGA where Ψ_ψᵀ·ε = 0, GNA where (Ψᵀ⁻¹·ε)_ψ = 0. Found by
/// bisection on the exact steady-state prediction error.
double fixed_point_psi(const MachinePu& plant, double n, const Vec2& u, const Vec2& e_u, bool gna) {
  auto direction = [&](double psi_hat) {
    MachinePu model = plant;
    model.psi_m_pu = psi_hat;
    const Vec2 i = steady_state_current(plant, n, u + e_u);
    const Vec2 i_hat = steady_state_current(model, n, u);
    const Mat2 g = steady_state_gradients(model, n, i_hat);
    const Vec2 eps = i - i_hat;
    return gna ? Vec2(g.inverse() * eps)[0] : g.col(0).dot(eps);
  };
  double lo = 0.9 * plant.psi_m_pu, hi = 1.1 * plant.psi_m_pu;
  const bool rising = direction(lo) > 0.0;  // the update moves ψ̂ up at lo
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    ((direction(mid) > 0.0) == rising ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(Gradients, SteadyStateBiasOfSgaAndGnaFromAVoltageError) {
  // docs/reproduction.md, difference 4: a voltage the model does not know (e_u = [δu_d, δu_q], plant side) shifts
  // the ψ̂m at which each algorithm settles by
  //   SGA:  δψ̂ = −δu_q/n + r_s·(x_d − x_q)/(n²·x_q² + r_s²)·δu_d
  //   GNA:  δψ̂ = −δu_q/n + î_q/(n·î_d)·δu_d            (R⁻¹: the ψ row of Ψᵀ⁻¹, orthogonal to the r̂s gradient)
  // At the bench's 0.3 pu the SGA's δu_d coefficient is −0.205; GNA's is î_q/(0.3·î_d), −14.9 at 0.4 pu load and
  // growing without bound towards no load (î_d → 0 under MTPA).
  const MachinePu m = test::paper_machine_pu();
  const double n = 0.3, e = 1e-8;  // small: GNA's response is large, and its coefficient depends on î_d
  const double sga_d = m.r_s_pu * (m.x_d_pu - m.x_q_pu) / (n * n * m.x_q_pu * m.x_q_pu + m.r_s_pu * m.r_s_pu);
  EXPECT_NEAR(sga_d, -0.205, 1e-3);
  for (const double torque : {0.4, 0.1, 0.02}) {
    SCOPED_TRACE(torque);
    const Vec2 i = mtpa_reference(m, torque);
    const Vec2 u = steady_state_voltage(m, n, i);
    const double gna_d = i[1] / (n * i[0]);
    if (torque == 0.4) {
      EXPECT_NEAR(gna_d, -14.95, 0.01);
    }
    for (const bool gna : {false, true}) {
      SCOPED_TRACE(gna ? "GNA" : "SGA");
      EXPECT_NEAR(fixed_point_psi(m, n, u, Vec2(0.0, e), gna) - m.psi_m_pu, -e / n, 0.01 * e / n);
      const double d_coeff = gna ? gna_d : sga_d;
      EXPECT_NEAR(fixed_point_psi(m, n, u, Vec2(e, 0.0), gna) - m.psi_m_pu, d_coeff * e, 0.02 * std::abs(d_coeff) * e);
    }
  }
}

}  // namespace
}  // namespace rpem::core
