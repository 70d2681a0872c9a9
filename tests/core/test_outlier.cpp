// The online outlier skip (RpemEstimator::outlier, docs/derivations.md §14): its false-skip rate under
// Gaussian noise is the derived one where D_M leaves nothing to explain; a glitch no parameter in D_M explains
// is skipped; a prediction error that a wrong ψ̂m explains, however suddenly it grows, is not.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rpem/core/estimator.hpp"
#include "support/paper_machine.hpp"
#include "support/seed.hpp"

namespace rpem::core {
namespace {

/// A steady window of the paper's machine at (n, τ), its current measured with noise.
SteadyStateSample window(const MachinePu& plant, double n, double torque, const Vec2& noise) {
  SteadyStateSample s;
  s.dt_s = 0.01;
  s.n_pu = n;
  const Vec2 i = mtpa_reference(plant, torque);
  s.u_pu = steady_state_voltage(plant, n, i);
  s.i_meas_pu = i + noise;
  s.i_gradient_pu = i;
  s.n_gradient_pu = n;
  return s;
}

Admission judged(double var_i) {
  Admission a;
  a.judge = true;
  a.var_i_pu = var_i;
  return a;
}

TEST(Outlier, FalseSkipRateUnderGaussianNoiseIsTheDerivedOne) {
  // D_M shrunk onto the machine: nothing is left to explain, and ε is the current's noise. A skip is a row
  // beyond ν·σ: rate 1 − (1 − erfc(ν/√2))², here at ν = 3 (the default 5 gives 1.15e-6, too rare to count).
  EstimatorConfig cfg = test::paper_config();
  const MachinePu plant = cfg.model;
  cfg.bounds.min_pu = Vec2(plant.psi_m_pu, plant.r_s_pu) * (1.0 - 1e-12);
  cfg.bounds.max_pu = Vec2(plant.psi_m_pu, plant.r_s_pu) * (1.0 + 1e-12);
  cfg.initial_theta_pu = Vec2(plant.psi_m_pu, plant.r_s_pu);
  cfg.outlier_bound_sigma = 3.0;
  RpemEstimator est(cfg);
  const std::uint64_t seed = test::test_seed(1423);
  std::mt19937_64 rng(seed);
  const double sigma = 1e-3;
  std::normal_distribution<double> noise(0.0, sigma);
  constexpr int kSamples = 200'000;
  long skipped = 0;
  for (int k = 0; k < kSamples; ++k) {
    const SteadyStateSample s = window(plant, 0.5, 0.5, Vec2(noise(rng), noise(rng)));
    skipped += est.step_steady_state(s, Vec2::Constant(1e-3), Vec2::Constant(1e-3), judged(sigma * sigma)).code ==
                       StepCode::kOutlier
                   ? 1
                   : 0;
  }
  const double one_row = std::erfc(3.0 / std::sqrt(2.0));
  const double p = 1.0 - (1.0 - one_row) * (1.0 - one_row);
  const double expected = p * kSamples, spread = std::sqrt(kSamples * p * (1.0 - p));
  EXPECT_NEAR(static_cast<double>(skipped), expected, 4.0 * spread) << "seed " << seed;
  // The default bound's rate, derived the same way.
  const double at_five = std::erfc(5.0 / std::sqrt(2.0));
  EXPECT_NEAR(1.0 - (1.0 - at_five) * (1.0 - at_five), 1.1466e-6, 1e-9);
}

TEST(Outlier, AGlitchIsSkippedAndCountedAndAdaptsNothing) {
  RpemEstimator est(test::paper_config());
  const MachinePu plant = test::paper_machine_pu();
  const double sigma = 1e-3;
  for (int k = 0; k < 10; ++k) {
    (void)est.step_steady_state(window(plant, 0.5, 0.5, Vec2::Zero()), Vec2::Constant(1e-3), Vec2::Constant(1e-3),
                                judged(sigma * sigma));
  }
  const Vec2 theta = est.state().theta_pu;
  // A current reading 2 pu off: more than any ψm or r_s inside D_M (paper: ψm 0.5-1.5×, r_s 0.44-2×) explains.
  const EstimatorOutput out = est.step_steady_state(window(plant, 0.5, 0.5, Vec2(0.0, 2.0)), Vec2::Constant(1e-3),
                                                    Vec2::Constant(1e-3), judged(sigma * sigma));
  EXPECT_EQ(out.code, StepCode::kOutlier);
  EXPECT_EQ(est.state().theta_pu, theta);
  EXPECT_GT(out.epsilon_pu.norm(), 1.9);
  // Unjudged (the plain estimator), the same reading adapts.
  EXPECT_EQ(
      est.step_steady_state(window(plant, 0.5, 0.5, Vec2(0.0, 2.0)), Vec2::Constant(1e-3), Vec2::Constant(1e-3), Admission{})
          .code,
      StepCode::kAdapted);
}

TEST(Outlier, APredictionErrorAWrongPsiMExplainsIsNotSkippedHoweverSuddenly) {
  // ψ̂m 40 % above the machine; from standstill (ε small) to 0.8 pu (ε large) in one sample.
  EstimatorConfig cfg = test::paper_config();
  cfg.initial_theta_pu[kPsiM] = 1.4 * cfg.model.psi_m_pu;
  RpemEstimator est(cfg);
  const MachinePu plant = test::paper_machine_pu();
  const double sigma = 1e-4;
  for (int k = 0; k < 20; ++k) {
    (void)est.step_steady_state(window(plant, 0.0, 0.3, Vec2::Zero()), Vec2::Constant(1e-3), Vec2::Constant(1e-3),
                                judged(sigma * sigma));
  }
  const EstimatorOutput out = est.step_steady_state(window(plant, 0.8, 0.3, Vec2::Zero()), Vec2::Constant(1e-3),
                                                    Vec2::Constant(1e-3), judged(sigma * sigma));
  EXPECT_EQ(out.code, StepCode::kAdapted);
  EXPECT_GT(out.epsilon_pu.norm(), 1000.0 * sigma);
}

}  // namespace
}  // namespace rpem::core
