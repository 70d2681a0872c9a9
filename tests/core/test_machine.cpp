// The closed-form steady-state analysis against the model equations and against the paper's printed
// eq_epsilon_steadystate, which (unlike eq:PEG_steadySTate_*) is printed correctly.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "rpem/core/machine.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

using test::kOmegaN;

/// eq_epsilon_steadystate as printed, with i the plant's (measured) current.
Vec2 printed_epsilon(const MachinePu& hat, double n, const Vec2& i, double d_psi, double d_rs, double d_xd, double d_xq) {
  const double D = hat.r_s_pu * hat.r_s_pu + n * n * hat.x_d_pu * hat.x_q_pu;
  const double r = hat.r_s_pu, xd = hat.x_d_pu, xq = hat.x_q_pu;
  const double ed = -(n * n * xq / D) * d_psi - (r / D * i[0] + n * xq / D * i[1]) * d_rs - (n * n * xq / D * i[0]) * d_xd +
                    (n * r / D * i[1]) * d_xq;
  const double eq = -(n * r / D) * d_psi - (r / D * i[1] - n * xd / D * i[0]) * d_rs - (n * r / D * i[0]) * d_xd -
                    (n * n * xd / D * i[1]) * d_xq;
  return {ed, eq};
}

class OperatingPlane : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(OperatingPlane, SteadyStateCurrentIsAnEquilibriumOfTheModel) {
  const auto [n, tau] = GetParam();
  const MachinePu m = test::paper_machine_pu();
  const Vec2 i_ref = mtpa_reference(m, tau);
  const Vec2 u = steady_state_voltage(m, n, i_ref);
  const Vec2 i = steady_state_current(m, n, u);
  EXPECT_LT((i - i_ref).norm(), 1e-12);
  EXPECT_LT(current_derivative(m, kOmegaN, n, i, u).norm(), 1e-9);
}

TEST_P(OperatingPlane, PredictionErrorMatchesPrintedSensitivities) {
  // Each parameter error alone: the printed expression (with the plant current) is exact, because the
  // steady-state model is linear in ψm, and M̂·ε = (M̂ − M)·i holds for r_s, x_d and x_q.
  const auto [n, tau] = GetParam();
  const MachinePu hat = test::paper_machine_pu();
  const Vec2 i_ref = mtpa_reference(hat, tau);
  struct Case {
    double dpsi, drs, dxd, dxq;
  };
  for (const Case c : {Case{-0.1 * hat.psi_m_pu, 0, 0, 0}, Case{0, -0.1 * hat.r_s_pu, 0, 0},
                       Case{0, 0, 0.05 * hat.x_d_pu, 0}, Case{0, 0, 0, -0.07 * hat.x_q_pu}}) {
    MachinePu plant = hat;
    plant.psi_m_pu += c.dpsi;
    plant.r_s_pu += c.drs;
    plant.x_d_pu += c.dxd;
    plant.x_q_pu += c.dxq;
    const Vec2 u = steady_state_voltage(plant, n, i_ref);  // the plant holds i_ref
    const Vec2 eps = steady_state_prediction_error(plant, hat, n, u);
    const Vec2 printed = printed_epsilon(hat, n, i_ref, c.dpsi, c.drs, c.dxd, c.dxq);
    EXPECT_LT((eps - printed).norm(), 1e-10 * std::max(1.0, printed.norm())) << "n=" << n << " tau=" << tau;
  }
}

TEST_P(OperatingPlane, EigenvaluesMatchEqLambda) {
  // Eq:lambda against a numerical eigen-solver of A: confirms Eq:lambda and the sign erratum E1 in
  // Eq:SystemMatrix (with the printed sign the eigenvalues would be real, one of them unstable).
  const auto [n, tau] = GetParam();
  (void)tau;
  const MachinePu m = test::paper_machine_pu();
  Eigen::EigenSolver<Mat2> es(system_matrix(m, kOmegaN, n));
  auto [l1, l2] = continuous_eigenvalues(m, kOmegaN, n);
  std::complex<double> e1 = es.eigenvalues()[0], e2 = es.eigenvalues()[1];
  if (std::abs(e1 - l1) > std::abs(e1 - l2)) std::swap(e1, e2);
  EXPECT_LT(std::abs(e1 - l1), 1e-9 * std::abs(l1));
  EXPECT_LT(std::abs(e2 - l2), 1e-9 * std::abs(l2));
  EXPECT_LT(l1.real(), 0.0);
  EXPECT_LT(l2.real(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(FourQuadrants, OperatingPlane,
                         ::testing::Combine(::testing::Values(-2.0, -0.8, -0.3, -0.05, 0.0, 0.005, 0.2, 1.0, 2.0),
                                            ::testing::Values(-1.0, -0.4, 0.0, 0.2, 0.6, 1.0)));

TEST(Mtpa, PrintedReferenceDeliversTorqueAndIsNearMinimumCurrent) {
  const MachinePu m = test::paper_machine_pu();
  for (double tau : {-1.5, -0.6, -0.2, 0.0, 0.1, 0.4, 1.0, 1.5}) {
    const Vec2 i = mtpa_reference(m, tau);
    EXPECT_NEAR(torque_pu(m, i), tau, 1e-12);
    // Independent check: golden-section search of min |i| along the constant-torque curve.
    auto norm_at = [&](double id) { return std::hypot(id, tau / (m.psi_m_pu - (m.x_q_pu - m.x_d_pu) * id)); };
    double lo = -2.0, hi = 0.0;
    for (int k = 0; k < 200; ++k) {
      const double a = lo + (hi - lo) / 3.0, b = hi - (hi - lo) / 3.0;
      if (norm_at(a) < norm_at(b)) {
        hi = b;
      } else {
        lo = a;
      }
    }
    // The printed closed form is an approximation: within 1e-4 of the minimum current up to 1.5 pu.
    EXPECT_LE(i.norm(), norm_at(0.5 * (lo + hi)) * (1.0 + 1e-4) + 1e-12) << "tau=" << tau;
    EXPECT_LE(i[0], 1e-15);
    // docs/derivations.md §7: the printed form's i_d is within 1.0 % of the exact MTPA's up to |τ| = 1.5 pu.
    if (tau != 0.0) {
      EXPECT_LT(std::abs(i[0] / (0.5 * (lo + hi)) - 1.0), 0.0105) << "tau=" << tau;
    }
  }
}

}  // namespace
}  // namespace rpem::core
