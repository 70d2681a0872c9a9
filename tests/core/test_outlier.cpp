// The online outlier skip (RpemEstimator::outlier, docs/derivations.md §14), judged on the evidence Ψᵀε the
// update acts through: its false-skip rate under Gaussian noise is the derived one where D_M leaves nothing to
// explain; a glitch no parameter in D_M explains is skipped; a prediction error that a wrong ψ̂m explains,
// however suddenly it grows, is not; nor is an error along no parameter's gradient (an inverter's voltage
// error on d at a crawl), which moves nothing.
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

/// P(|z₁| ≤ ν, |z₂| ≤ ν) for standard normals of correlation ρ: ∫ φ(x)·P(|z₂| ≤ ν | z₁ = x) dx over [−ν, ν]
/// (Simpson's rule; z₂ | x is normal, mean ρx, variance 1 − ρ²).
double both_within(double nu, double rho) {
  const auto phi = [](double x) { return std::exp(-0.5 * x * x) / std::sqrt(2.0 * M_PI); };
  const auto cdf = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  const double s = std::sqrt(1.0 - rho * rho);
  const auto f = [&](double x) { return phi(x) * (cdf((nu - rho * x) / s) - cdf((-nu - rho * x) / s)); };
  constexpr int kIntervals = 2000;
  const double h = 2.0 * nu / kIntervals;
  double sum = f(-nu) + f(nu);
  for (int k = 1; k < kIntervals; ++k) sum += (k % 2 == 1 ? 4.0 : 2.0) * f(-nu + k * h);
  return sum * h / 3.0;
}

TEST(Outlier, FalseSkipRateUnderGaussianNoiseIsTheDerivedOne) {
  // D_M shrunk onto the machine: nothing is left to explain, and ε is the current's noise n (covariance σ²·I).
  // A skip is an evidence z_j = Ψ_jᵀn beyond ν·σ·|Ψ_j| for ψm or r_s; the two are normal with correlation
  // ρ = Ψ_ψᵀΨ_r/(|Ψ_ψ|·|Ψ_r|), so the rate is 1 − P(|z₁| ≤ ν, |z₂| ≤ ν), here at ν = 3 (the default 5 gives
  // at most 2·erfc(5/√2) = 1.15e-6, too rare to count).
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
  Mat2 gradient = Mat2::Zero();  // the same at every sample: θ̂ and the operating point do not move
  for (int k = 0; k < kSamples; ++k) {
    const SteadyStateSample s = window(plant, 0.5, 0.5, Vec2(noise(rng), noise(rng)));
    const EstimatorOutput out = est.step_steady_state(s, Vec2::Constant(1e-3), Vec2::Constant(1e-3), judged(sigma * sigma));
    if (out.code == StepCode::kOutlier) ++skipped;
    if (out.code == StepCode::kAdapted) gradient = out.gradient;
  }
  const double rho = gradient.col(kPsiM).dot(gradient.col(kRs)) / (gradient.col(kPsiM).norm() * gradient.col(kRs).norm());
  ASSERT_TRUE(std::isfinite(rho));
  const double p = 1.0 - both_within(3.0, rho);
  // The two limits it lies between: one evidence alone (ρ = ±1), two independent ones (ρ = 0).
  const double one = std::erfc(3.0 / std::sqrt(2.0));
  ASSERT_GE(p, one * (1.0 - 1e-9));
  ASSERT_LE(p, 1.0 - (1.0 - one) * (1.0 - one) + 1e-12);
  EXPECT_NEAR(1.0 - both_within(3.0, 0.0), 1.0 - (1.0 - one) * (1.0 - one), 1e-9);
  const double expected = p * kSamples, spread = std::sqrt(kSamples * p * (1.0 - p));
  EXPECT_NEAR(static_cast<double>(skipped), expected, 4.0 * spread) << "seed " << seed << ", rho " << rho;
  // The default bound's rate at its worst (two independent evidences), derived the same way.
  EXPECT_NEAR(1.0 - both_within(5.0, 0.0), 1.1466e-6, 1e-9);
}

TEST(Outlier, AGlitchIsSkippedAndCountedAndAdaptsNothing) {
  RpemEstimator est(test::paper_config());
  const MachinePu plant = test::paper_machine_pu();
  const double sigma = 1e-3;
  for (int k = 0; k < 10; ++k) {
    (void)est.step_steady_state(window(plant, 0.0, 0.5, Vec2::Zero()), Vec2::Constant(1e-3), Vec2::Constant(1e-3),
                                judged(sigma * sigma));
  }
  const Vec2 theta = est.state().theta_pu;
  // At standstill, where r_s adapts, a current reading 2 pu off: its evidence on r_s is more than any r_s
  // inside D_M (paper: 0.44-2×) explains.
  const EstimatorOutput out = est.step_steady_state(window(plant, 0.0, 0.5, Vec2(0.0, 2.0)), Vec2::Constant(1e-3),
                                                    Vec2::Constant(1e-3), judged(sigma * sigma));
  EXPECT_EQ(out.code, StepCode::kOutlier);
  EXPECT_EQ(est.state().theta_pu, theta);
  EXPECT_GT(out.epsilon_pu.norm(), 1.9);
  // Unjudged (the plain estimator), the same reading adapts.
  EXPECT_EQ(
      est.step_steady_state(window(plant, 0.0, 0.5, Vec2(0.0, 2.0)), Vec2::Constant(1e-3), Vec2::Constant(1e-3), Admission{})
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

TEST(Outlier, AnErrorAlongNoParametersGradientMovesNothingAndIsNotSkipped) {
  // A crawl with i_d held at 0: both gradient columns lie along q to within n·x_q/r (0.005 here, as a VESC
  // Hall drive's crawl at 10 rad/s), so a d error moves neither parameter. The d voltage carries an
  // inverter's error (0.05·u_q: hundreds of the noise's σ, and about five times what any θ in D_M puts on the d row),
  // and r̂s starts 20 % high: the sample adapts r̂s towards the machine, as one without the d error does,
  // instead of being skipped for a d row no parameter explains.
  EstimatorConfig cfg = test::paper_config();
  cfg.initial_theta_pu[kRs] = 1.2 * cfg.model.r_s_pu;
  const MachinePu plant = test::paper_machine_pu();
  const double sigma = 1e-4, n = 0.005 * plant.r_s_pu / plant.x_q_pu;
  SteadyStateSample s;
  s.dt_s = 0.01;
  s.n_pu = s.n_gradient_pu = n;
  s.i_meas_pu = s.i_gradient_pu = Vec2(0.0, 0.5);
  s.u_pu = steady_state_voltage(plant, n, s.i_meas_pu);
  SteadyStateSample with_error = s;
  with_error.u_pu[0] += 0.05 * s.u_pu[1];
  RpemEstimator clean(cfg), disturbed(cfg);
  const EstimatorOutput a = clean.step_steady_state(s, Vec2::Constant(1e-3), Vec2::Constant(1e-3), judged(sigma * sigma));
  const EstimatorOutput b =
      disturbed.step_steady_state(with_error, Vec2::Constant(1e-3), Vec2::Constant(1e-3), judged(sigma * sigma));
  // The d error: hundreds of the noise's σ (a bound on each row's error would skip it) ...
  EXPECT_GT(std::abs(b.epsilon_pu[0] - a.epsilon_pu[0]), 100.0 * sigma);
  // ... but it lies along no column: its evidence on r_s is a small part of the q error's.
  const Mat2& g = b.gradient;
  const double d_part = std::abs(g(0, kRs) * (b.epsilon_pu[0] - a.epsilon_pu[0]));
  EXPECT_LT(d_part, 0.05 * std::abs(g(1, kRs) * a.epsilon_pu[1]));
  EXPECT_EQ(a.code, StepCode::kAdapted);
  EXPECT_EQ(b.code, StepCode::kAdapted);
  EXPECT_LT(b.theta_pu[kRs], cfg.initial_theta_pu[kRs]);
  EXPECT_NEAR(b.theta_pu[kRs], a.theta_pu[kRs], 0.05 * (cfg.initial_theta_pu[kRs] - a.theta_pu[kRs]));
}

}  // namespace
}  // namespace rpem::core
