// The scalar R_s recursion at standstill (analysis/standstill_rs.hpp, docs/derivations.md E5) against
// closed forms and an independent computation.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/analysis/standstill_rs.hpp"

namespace rpem::analysis {
namespace {

constexpr double kTs = 125e-6;

TEST(StandstillRs, LinearisedBoundWithoutMemoryIsAGeometricDecay) {
  // γ_r = 1: R is always the settled Ψ², the rate is γ_L every sample, e_k = e_0·(1 − γ_L)^k.
  const double gL = 1e-3, e0 = 0.08;
  const double k = std::ceil(std::log(0.01 / e0) / std::log(1.0 - gL));
  EXPECT_NEAR(*linearised_rs_bound_s(1.0, gL, kTs, e0), k * kTs, 1e-12);
}

TEST(StandstillRs, LinearisedBoundForTabPsimgainsGnaColumnIsTheIndependentFigure) {
  // tab_psimgains' GNA R_s column, R[0] → 0: 13.93475 s from 8 %, 2.9115 s from 4 %, 15.3235 s from 8/0.92 − 1
  // (the same product ∏(1 − γ_L/(1 − (1 − γ_r)^k)) evaluated independently in Python, sample by sample).
  EXPECT_NEAR(*linearised_rs_bound_s(6.25e-5, 7.5e-6, kTs, 0.08), 13.93475, 1e-9);
  EXPECT_NEAR(*linearised_rs_bound_s(6.25e-5, 7.5e-6, kTs, 0.04), 2.9115, 1e-9);
  EXPECT_NEAR(*linearised_rs_bound_s(6.25e-5, 7.5e-6, kTs, 1.0 / 0.92 - 1.0), 15.3235, 1e-9);
}

TEST(StandstillRs, SettledRecursionIsTheLogisticApproach) {
  // R settled at Ψ² (γ_r = 1): x' = −γ_L·x·(1 + x) per sample, whose continuous solution is
  // x/(1 + x) = x0/(1 + x0)·exp(−γ_L·k): the time into ±1 % is T/γ_L·ln((x0/(1+x0)) / (0.01/1.01)).
  const StandstillRs m{1.0, 1e-4, kTs, 1.0};
  const double x0 = 1.0 / 0.92 - 1.0;
  const double expected = kTs / m.gamma_L * std::log((x0 / (1.0 + x0)) / (0.01 / 1.01));
  EXPECT_NEAR(*standstill_rs_time_s(m, x0), expected, 2e-3 * expected);
  // From below the same rate law with x < 0.
  const double xm = -0.08;
  EXPECT_NEAR(*standstill_rs_time_s(m, xm), kTs / m.gamma_L * std::log((xm / (1.0 + xm)) / (-0.01 / 0.99)), 2e-3 * expected);
}

TEST(StandstillRs, FallingEstimateConvergesFasterThanTheLinearisation) {
  // From above, Ψ and ε grow as r̂s falls: the exact recursion beats its linearisation, by less than a quarter.
  const StandstillRs gna{6.25e-5, 7.5e-6, kTs, 0.0};
  for (const double e0 : {0.04, 0.08, 0.087}) {
    const double exact = *standstill_rs_time_s(gna, e0);
    const double lin = *linearised_rs_bound_s(gna.gamma_r, gna.gamma_L, kTs, e0);
    EXPECT_LT(exact, lin) << e0;
    EXPECT_GT(exact, 0.75 * lin) << e0;
  }
}

TEST(StandstillRs, ALargerInitialHessianIsNeverFaster) {
  const double e0 = 0.087;
  double previous = 0.0;
  for (const double r0 : {0.0, 0.01, 0.1, 1.0, 10.0}) {
    const double t = *standstill_rs_time_s({6.25e-4, 6.25e-5, kTs, r0}, e0);
    EXPECT_GE(t, previous) << r0;
    previous = t;
  }
}

TEST(StandstillRs, InitialErrorForATimeInvertsTheTime) {
  const StandstillRs gna{6.25e-5, 7.5e-6, kTs, 0.0};
  for (const double t : {4.0, 8.0, 20.0}) {
    const auto e0 = standstill_rs_initial_error_for(gna, t);
    ASSERT_TRUE(e0) << t;
    EXPECT_NEAR(*standstill_rs_time_s(gna, *e0), t, 2.0 * kTs) << t;
    EXPECT_LT(std::abs(standstill_rs_error_after(gna, *e0, t)), 0.01 + 1e-9) << t;
  }
  // SGA's column reaches 1 % from any start up to 100 % long before 30 s.
  EXPECT_FALSE(standstill_rs_initial_error_for({6.25e-4, 6.25e-5, kTs, 1.0}, 30.0));
}

}  // namespace
}  // namespace rpem::analysis
