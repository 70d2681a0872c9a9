// The averaged-sample estimator (core/averaged_estimator.hpp, docs/derivations.md §11) on windows whose
// means are computed from the machine equations (support/averaged_data.hpp): exact answers where the
// model is exact, rate-independent time constants, gaps, and the corrections.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/averaged_estimator.hpp"
#include "support/averaged_data.hpp"
#include "support/paper_machine.hpp"
#include "support/seed.hpp"

namespace rpem::core {
namespace {

test::AveragedDataGenerator averaged_generator(double rate_Hz, double n, double tau, double psi_scale = 1.0,
                                               double rs_scale = 1.0) {
  test::AveragedDataGenerator g;
  g.base = test::paper_base();
  g.plant = test::paper_machine_pu();
  g.plant.psi_m_pu *= psi_scale;
  g.plant.r_s_pu *= rs_scale;
  g.rate_Hz = rate_Hz;
  const Vec2 i = mtpa_reference(g.plant, tau);
  g.n_pu = [n](double) { return n; };
  g.i_pu = [i](double) { return i; };
  return g;
}

struct AveragedRun {
  Estimate last;
  double psi_m_rel = 0.0;  ///< ψ̂m / true ψm
  double r_s_rel = 0.0;
};

AveragedRun run(AveragedDriveEstimator& est, test::AveragedDataGenerator& g, double seconds) {
  AveragedRun r;
  while (g.t_s < seconds) r.last = est.step(g.next());
  r.psi_m_rel = est.psi_m_Wb() / g.base.flux_Wb_of(g.plant.psi_m_pu);
  r.r_s_rel = est.r_s_Ohm() / g.base.resistance_Ohm_of(g.plant.r_s_pu);
  return r;
}

TEST(AveragedEstimator, TrueParametersGiveZeroPredictionErrorOnSteadyWindows) {
  auto g = averaged_generator(200.0, 0.4, 0.5);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  for (int k = 0; k < 200; ++k) {
    const Estimate e = est.step(g.next());
    EXPECT_LT(e.epsilon_A.norm(), 1e-9 * g.base.current_A) << "k=" << k;
    if (k > 0) {
      EXPECT_EQ(e.detail.code, StepCode::kAdapted);
    }
  }
  EXPECT_NEAR(est.psi_m_Wb(), 1.14, 1e-12);
}

TEST(AveragedEstimator, PredictionErrorIsEqEpsilonSteadyState) {
  // ψm 5 % low and R_s 10 % high in the machine: the first sample's ε is eq_epsilon_steadystate exactly.
  auto g = averaged_generator(200.0, 0.4, 0.5, 0.95, 1.1);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  const AveragedSample s = g.next();
  const Estimate e = est.step(s);
  const Vec2 u_pu = s.u_dq_V / g.base.voltage_V;
  const Vec2 expected = steady_state_prediction_error(g.plant, test::paper_machine_pu(), 0.4, u_pu);
  EXPECT_LT((e.detail.epsilon_pu - expected).norm(), 1e-12);
  EXPECT_EQ(e.detail.code, StepCode::kSynchronized);  // the first sample adapts nothing
}

/// The time [s] ψ̂m's error takes to fall from 1/e to 1/e³ of its start, at a sample rate (crossings
/// log-linear between samples; measured after the start, so the first window, which only anchors the
/// chain and is 20 ms long at 50 Hz, does not count).
double psi_m_decay_time(double rate_Hz, std::uint64_t seed) {
  auto g = averaged_generator(rate_Hz, 0.5, 0.4, 0.92);
  g.rng.seed(seed);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  const double truth = g.base.flux_Wb_of(g.plant.psi_m_pu);
  const double start = std::log(std::abs(1.14 / truth - 1.0));
  double crossing[2] = {0.0, 0.0};
  int next = 0;
  double t_before = 0.0, log_before = start;
  while (g.t_s < 20.0 && next < 2) {
    (void)est.step(g.next());
    const double log_now = std::log(std::abs(est.psi_m_Wb() / truth - 1.0));
    const double target = start - (next == 0 ? 1.0 : 3.0);
    if (log_now < target) {
      crossing[next++] = t_before + (g.t_s - t_before) * (log_before - target) / (log_before - log_now);
    }
    t_before = g.t_s;
    log_before = log_now;
  }
  return next == 2 ? crossing[1] - crossing[0] : 1e9;
}

TEST(AveragedEstimator, OneConfigurationGivesTheSameTimeConstantAtEveryRate) {
  // Gains are rates per second (γ = 1 − e^{−rate·h}): the same convergence in seconds from 50 Hz to 2 kHz,
  // uneven windows included. The paper's SGA ψm gain is 3.25e-4 per 125 µs = 2.6 /s.
  const std::uint64_t seed = test::test_seed(12);
  const double t1000 = psi_m_decay_time(1000.0, seed);
  for (double rate : {50.0, 200.0, 2000.0}) {
    EXPECT_NEAR(psi_m_decay_time(rate, seed) / t1000, 1.0, 0.02) << "rate " << rate << " Hz, seed " << seed;
  }
  EXPECT_GT(t1000, 0.2);
  EXPECT_LT(t1000, 4.0);
}

class AtRate : public ::testing::TestWithParam<double> {};

TEST_P(AtRate, PsiMConvergesAtSpeed) {
  auto g = averaged_generator(GetParam(), -0.6, 0.5, 0.92);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  const AveragedRun r = run(est, g, 6.0);
  EXPECT_NEAR(r.psi_m_rel, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(est.r_s_Ohm(), 2.25);  // scheduled out at speed
  EXPECT_TRUE(r.last.detail.flags & step_flag::kPsiMActive);
}

TEST_P(AtRate, RsConvergesAtStandstillUnderLoad) {
  auto g = averaged_generator(GetParam(), 0.0, 0.4, 1.0, 1.15);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  const AveragedRun r = run(est, g, 30.0);
  EXPECT_NEAR(r.r_s_rel, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(est.psi_m_Wb(), 1.14);
  EXPECT_TRUE(r.last.detail.flags & step_flag::kRsActive);
}

INSTANTIATE_TEST_SUITE_P(Rates, AtRate, ::testing::Values(50.0, 200.0, 1000.0),
                         [](const auto& p) { return std::to_string(static_cast<int>(p.param)) + "Hz"; });

TEST(AveragedEstimator, InductiveCorrectionIsExactOnACurrentRampAndNeededThere) {
  // i_q rises at 2 pu/s at n = 0.3 pu: the windows' means carry (x/ω_n)·di/dt, which the steady state
  // leaves out. With the correction (backward difference of window means: exact for a ramp) ε vanishes.
  auto make = [] {
    auto g = averaged_generator(500.0, 0.3, 0.0);
    g.i_pu = [](double t) { return Vec2(-0.1, 0.2 + 2.0 * t); };
    g.di_pu_per_s = [](double) { return Vec2(0.0, 2.0); };
    return g;
  };
  EstimatorSettings settings = test::paper_settings();
  settings.adapt_psi_m = settings.adapt_r_s = false;
  // ε = −M⁻¹·(x/ω_n)·di/dt without the correction (the term the plain steady state leaves out).
  const MachinePu m = test::paper_machine_pu();
  auto g = make();
  const Vec2 term = Vec2(0.0, m.x_q_pu * 2.0) / g.base.omega_el_rad_s;
  const Vec2 expected = steady_state_current(m, 0.3, term) - steady_state_current(m, 0.3, Vec2::Zero());
  // With it, ε is zero up to the nanosecond rounding of the window times (relative 1e-6 of the term).
  AveragedDriveEstimator with(test::paper_machine_si(), settings);
  for (int k = 0; k < 100; ++k) {
    const Estimate e = with.step(g.next());
    if (k > 0) {
      EXPECT_LT(e.detail.epsilon_pu.norm(), 1e-6 * expected.norm()) << "k=" << k;
    }
  }
  settings.averaged.inductive_correction = false;
  g = make();
  AveragedDriveEstimator without(test::paper_machine_si(), settings);
  Estimate e;
  for (int k = 0; k < 100; ++k) e = without.step(g.next());
  EXPECT_LT((e.detail.epsilon_pu + expected).norm(), 1e-6 * expected.norm());
  EXPECT_GT(expected.norm(), 1e-3);
}

TEST(AveragedEstimator, GapsAndLongIntervalsAdaptNothing) {
  auto g = averaged_generator(200.0, 0.4, 0.5, 0.95);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  EXPECT_EQ(est.step(g.next()).detail.code, StepCode::kSynchronized);
  EXPECT_EQ(est.step(g.next()).detail.code, StepCode::kAdapted);
  AveragedSample s = g.next();
  s.gap_before = true;
  EXPECT_EQ(est.step(s).detail.code, StepCode::kSynchronized);
  const Vec2 theta = est.core().state().theta_pu;
  EXPECT_EQ(est.step(g.next()).detail.code, StepCode::kAdapted);
  EXPECT_NE(est.core().state().theta_pu, theta);
  // A window starting later than the previous one ended (by more than half its length): windows were lost. It adapts
  // nothing, and the window before the lost ones, which no successor judged, is retracted (docs/derivations.md §13,
  // "A chain's last window"): θ̂ is back where it stood before that window.
  (void)g.next();
  EXPECT_EQ(est.step(g.next()).detail.code, StepCode::kSynchronized);
  EXPECT_EQ(est.core().state().theta_pu, theta);
  // An interval beyond averaged.max_interval_s (50 ms).
  g.t_s += 0.1;
  s = g.next();
  s.t_start_ns = s.t_ns - 5'000'000;
  EXPECT_EQ(est.step(s).detail.code, StepCode::kSynchronized);
  EXPECT_EQ(est.step(g.next()).detail.code, StepCode::kAdapted);
}

TEST(AveragedEstimator, InstantaneousSamplesAreAcceptedWithTheirSpacing) {
  // A source that samples instead of averaging (t_start = t): consecutive samples continue the chain.
  auto g = averaged_generator(200.0, 0.5, 0.4, 0.92);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  Estimate e;
  while (g.t_s < 6.0) {
    AveragedSample s = g.next();
    s.t_start_ns = s.t_ns;
    e = est.step(s);
  }
  EXPECT_EQ(e.detail.code, StepCode::kAdapted);
  EXPECT_NEAR(est.psi_m_Wb() / g.base.flux_Wb_of(g.plant.psi_m_pu), 1.0, 1e-3);
}

TEST(AveragedEstimator, NonFiniteSampleIsRejectedAndTheChainRestarts) {
  auto g = averaged_generator(200.0, 0.4, 0.5, 0.95);
  AveragedDriveEstimator est(test::paper_machine_si(), test::paper_settings());
  for (int k = 0; k < 9; ++k) (void)est.step(g.next());
  const Vec2 theta = est.core().state().theta_pu;
  (void)est.step(g.next());
  EXPECT_NE(est.core().state().theta_pu, theta);
  AveragedSample bad = g.next();
  bad.u_dq_V[1] = std::nan("");
  EXPECT_EQ(est.step(bad).detail.code, StepCode::kRejectedNonFinite);
  // It adapts nothing, and the window before it, which it cannot judge for a bridge release inside, is retracted
  // (docs/derivations.md §13, "A chain's last window").
  EXPECT_EQ(est.core().state().theta_pu, theta);
  EXPECT_EQ(est.step(g.next()).detail.code, StepCode::kAdapted);  // the last finite sample anchors the chain
}

TEST(AveragedEstimator, DelayAndAngleOffsetExtensionsUndoTheirEffect) {
  // A drive whose voltage acts 150 µs late and whose angle reads 0.05 rad behind: its reported means are
  // the true ones turned by +ω·delay (voltage) and by −offset (both; true = logged + offset).
  auto g = averaged_generator(200.0, 0.8, 0.5);
  EstimatorSettings settings = test::paper_settings();
  settings.extensions.delay_s = 150e-6;
  settings.extensions.theta_offset_rad = 0.05;
  AveragedDriveEstimator est(test::paper_machine_si(), settings);
  const double omega = g.base.omega_el_rad_s_of(0.8);
  auto turn = [](const Vec2& v, double a) {
    return Vec2(std::cos(a) * v[0] - std::sin(a) * v[1], std::sin(a) * v[0] + std::cos(a) * v[1]);
  };
  for (int k = 0; k < 50; ++k) {
    AveragedSample s = g.next();
    s.u_dq_V = turn(turn(s.u_dq_V, omega * 150e-6), 0.05);
    s.i_dq_A = turn(s.i_dq_A, 0.05);
    EXPECT_LT(est.step(s).epsilon_A.norm(), 1e-9) << "k=" << k;
  }
}

TEST(AveragedEstimator, ExplicitRatesPerSecondOverrideTheNativeGains) {
  EstimatorSettings s = test::paper_settings();
  auto rates = averaged_rates_per_s(s);
  EXPECT_NEAR(rates[0].gain[kPsiM], 3.25e-4 / 125e-6, 1e-12);
  EXPECT_NEAR(rates[1].hessian[kRs], 6.25e-5 / 125e-6, 1e-12);
  s.averaged.rates_given[0] = true;
  s.averaged.rates_per_s[0] = {Vec2(1.0, 2.0), Vec2(3.0, 4.0)};
  rates = averaged_rates_per_s(s);
  EXPECT_EQ(rates[0].gain, Vec2(3.0, 4.0));
  EXPECT_NEAR(rates[2].gain[kRs], 0.5, 1e-12);
}

}  // namespace
}  // namespace rpem::core
