// Fig_EigenTraj (b): at T_samp = 125 µs the trapezoidal predictor is stable for |n| ≤ 2 pu, explicit
// Euler is not. Eigenvalues come from a numerical eigen-solver of the one-step transition matrix.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "rpem/core/predictor.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

using test::kDt;
using test::kOmegaN;

double spectral_radius(Discretization d, double n) {
  Eigen::EigenSolver<Mat2> es(transition_matrix(test::paper_machine_pu(), kOmegaN, d, kDt, n));
  return std::max(std::abs(es.eigenvalues()[0]), std::abs(es.eigenvalues()[1]));
}

TEST(PredictorStability, TrapezoidalStaysInsideTheUnitCircleUpToTwoPu) {
  for (double n = -2.0; n <= 2.0 + 1e-12; n += 0.01) {
    EXPECT_LT(spectral_radius(Discretization::kTrapezoidal, n), 1.0) << "n=" << n;
  }
}

TEST(PredictorStability, ExplicitEulerLeavesTheUnitCircleWhereTheAnalysisSays) {
  // |1 + hλ|² = 1 with λ = −σ ± jω_i gives ω_i² = (2σ − hσ²)/h; ω_i² = (ω_n·n)² + 1/(T_dT_q) − σ².
  const MachinePu m = test::paper_machine_pu();
  const double inv_td = m.r_s_pu * kOmegaN / m.x_d_pu, inv_tq = m.r_s_pu * kOmegaN / m.x_q_pu;
  const double sigma = 0.5 * (inv_td + inv_tq);
  const double wi2 = (2.0 * sigma - kDt * sigma * sigma) / kDt;
  const double n_boundary = std::sqrt(wi2 - inv_td * inv_tq + sigma * sigma) / kOmegaN;
  EXPECT_NEAR(n_boundary, 1.67, 0.005);  // docs/derivations.md §4, the paper's machine at 125 µs
  for (double sign : {-1.0, 1.0}) {
    EXPECT_LT(spectral_radius(Discretization::kExplicitEuler, sign * 0.99 * n_boundary), 1.0);
    EXPECT_GT(spectral_radius(Discretization::kExplicitEuler, sign * 1.01 * n_boundary), 1.0);
    EXPECT_GT(spectral_radius(Discretization::kExplicitEuler, sign * 2.0), 1.0);
  }
}

TEST(PredictorStability, TrapezoidalMapsEachContinuousEigenvalueByTheBilinearRule) {
  const MachinePu m = test::paper_machine_pu();
  for (double n : {0.0, 0.3, 1.0, 2.0}) {
    auto [l1, l2] = continuous_eigenvalues(m, kOmegaN, n);
    Eigen::EigenSolver<Mat2> es(transition_matrix(m, kOmegaN, Discretization::kTrapezoidal, kDt, n));
    for (auto l : {l1, l2}) {
      const std::complex<double> z = (1.0 + 0.5 * kDt * l) / (1.0 - 0.5 * kDt * l);
      const double d = std::min(std::abs(es.eigenvalues()[0] - z), std::abs(es.eigenvalues()[1] - z));
      EXPECT_LT(d, 1e-12) << "n=" << n;
    }
  }
}

}  // namespace
}  // namespace rpem::core
