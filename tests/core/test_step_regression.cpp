// DriveEstimator::step gives, to 1e-12 relative, the estimates it gave before issue 11's rework of its
// per-sample path (conditioner and estimator core): a fixed SI phase-sample sequence (the paper's
// machine, ψm 5 % and r_s 10 % off the configuration, sensor noise, one lost sample) through every
// algorithm and gradient form, and through the conditioner with every model extension active. The
// expected figures were recorded from the code before that rework (commit 9a436ed on branch step-11);
// they pin behaviour, not correctness — the other estimator tests check the numbers against derivations.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "rpem/core/drive_estimator.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

/// What a run leaves: the final estimates and sums over every sample's outputs.
struct Fingerprint {
  double psi_m_Wb, r_s_Ohm;
  double epsilon_sum_A;    ///< Σ (ε_d + 2·ε_q)
  double i_hat_sum_A;      ///< Σ (î_d + 2·î_q)
  double gain_sum;         ///< Σ of every element of L
  std::uint64_t flag_sum;  ///< Σ (code·256 + flags)
};

Fingerprint run(const EstimatorSettings& settings, double n_pu, double torque_pu) {
  const PerUnitBase base = test::paper_base();
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.plant.psi_m_pu *= 0.95;
  gen.plant.r_s_pu *= 1.1;
  gen.omega_n_rad_s = base.omega_el_rad_s;
  gen.n_pu = n_pu;
  gen.i_ref_pu = mtpa_reference(gen.plant, torque_pu);
  gen.current_noise_pu = 0.002;
  DriveEstimator est(test::paper_machine_si(), settings);
  Fingerprint f{};
  std::int64_t t_ns = 0;
  for (int k = 0; k < 4000; ++k) {
    DriveSample s = gen.next_si(base, t_ns);
    if (k == 2000) continue;  // lost: the next one carries gap_before
    s.gap_before = k == 2001;
    const Estimate e = est.step(s);
    f.epsilon_sum_A += e.epsilon_A[0] + 2.0 * e.epsilon_A[1];
    f.i_hat_sum_A += e.i_hat_A[0] + 2.0 * e.i_hat_A[1];
    f.gain_sum += e.detail.gain.sum();
    f.flag_sum += static_cast<std::uint64_t>(e.detail.code) * 256U + e.detail.flags;
  }
  f.psi_m_Wb = est.psi_m_Wb();
  f.r_s_Ohm = est.r_s_Ohm();
  return f;
}

void expect_same(const Fingerprint& got, const Fingerprint& want) {
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(b), 1e-3); };
  EXPECT_PRED2(near, got.psi_m_Wb, want.psi_m_Wb);
  EXPECT_PRED2(near, got.r_s_Ohm, want.r_s_Ohm);
  EXPECT_PRED2(near, got.epsilon_sum_A, want.epsilon_sum_A);
  EXPECT_PRED2(near, got.i_hat_sum_A, want.i_hat_sum_A);
  EXPECT_PRED2(near, got.gain_sum, want.gain_sum);
  EXPECT_EQ(got.flag_sum, want.flag_sum);
  // On failure, the run's figures in full (to record them after an intended change of behaviour).
  if (testing::Test::HasFailure()) {
    std::printf("{%.17g, %.17g, %.17g, %.17g, %.17g, %llu}\n", got.psi_m_Wb, got.r_s_Ohm, got.epsilon_sum_A, got.i_hat_sum_A,
                got.gain_sum, static_cast<unsigned long long>(got.flag_sum));
  }
}

EstimatorSettings settings(Algorithm algorithm, GradientForm form) {
  EstimatorSettings s = test::paper_settings(algorithm);
  s.gradient_psi_m = s.gradient_r_s = form;
  return s;
}

TEST(StepRegression, SgaSteadyState) {
  expect_same(run(settings(Algorithm::kSga, GradientForm::kSteadyState), 0.4, 0.4),
              {1.1043698056020574, 2.25, 1332.3749023572254, 16297.304846265364, -0.79736476438691184, 128416});
}
TEST(StepRegression, SgaDynamic) {
  expect_same(run(settings(Algorithm::kSga, GradientForm::kDynamic), 0.4, 0.4),
              {1.1045625396287464, 2.25, 1338.2310364339387, 16291.446552833246, -0.78869820326017792, 128416});
}
TEST(StepRegression, SgaSteadyStateAtStandstill) {
  expect_same(
      run(settings(Algorithm::kSga, GradientForm::kSteadyState), 0.005, 0.4),
      {1.1399999999999999, 2.3051392918094313, -1078.1321631702299, 18789.607862807734, -0.074797924288415946, 256320});
}
TEST(StepRegression, GnaSteadyState) {
  expect_same(run(settings(Algorithm::kGna, GradientForm::kSteadyState), 0.4, 0.4),
              {1.1033170059731243, 2.25, 1310.0256726050668, 16319.659646944383, -0.40425615293053407, 128416});
}
TEST(StepRegression, GnaDynamic) {
  expect_same(run(settings(Algorithm::kGna, GradientForm::kDynamic), 0.4, 0.4),
              {1.10200931919443, 2.25, 1254.974206992493, 16374.738200704003, -0.48349886152241012, 128416});
}
TEST(StepRegression, PhyIntSteadyState) {
  expect_same(run(settings(Algorithm::kPhyInt, GradientForm::kSteadyState), 0.4, 0.4),
              {1.1020131579382708, 2.25, 1408.5068195697129, 16221.150090914041, -0.83024799959667805, 128416});
}
TEST(StepRegression, PhyIntDynamic) {
  expect_same(run(settings(Algorithm::kPhyInt, GradientForm::kDynamic), 0.4, 0.4),
              {1.1020131579382708, 2.25, 1408.5068195697129, 16221.150090914041, -0.83024799959667805, 128416});
}

TEST(StepRegression, SgaWithEveryExtension) {
  EstimatorSettings s = settings(Algorithm::kSga, GradientForm::kSteadyState);
  ModelExtensions& x = s.extensions;
  x.theta_offset_rad = 0.02;
  x.current_offset_A = Vec3(0.05, -0.03, 0.0);
  x.current_gain_error = Vec3(0.01, -0.005, 0.0);
  x.deadtime_v_err_V = 0.8;
  x.deadtime_t_dead_s = 1e-6;
  x.switching_frequency_Hz = 8000.0;
  x.deadtime_current_band_A = 0.2;
  x.delay_s = 1.5 * 125e-6;
  x.inductance_d = {1.0, -1e-4, 2e-3};
  x.inductance_q = {0.98, -2e-4, 0.0};
  x.cross_coupling_H_per_A = 1e-6;
  x.cross_coupling_H_per_A2 = 1e-8;
  x.iron_loss_r_fe_Ohm = 300.0;
  x.flux_harmonics[0] = {1e-3, -5e-4, 2e-4, 3e-4};
  x.flux_harmonics[1] = {0.0, 2e-4, -1e-4, 0.0};
  expect_same(run(s, 0.4, 0.4),
              {1.0808634875239533, 2.25, 172.14222246577435, 14897.360554112431, -0.84528736795419468, 128416});
}

}  // namespace
}  // namespace rpem::core
