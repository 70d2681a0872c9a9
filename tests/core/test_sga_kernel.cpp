// The hand-written SGA kernel that bench_estimator uses as its baseline computes what RpemEstimator
// computes (SGA, dynamic gradients, same samples): θ̂, î and the gradients agree to round-off over
// thousands of samples, with ψ̂m adapting (0.4 pu) and with r̂s adapting (standstill region).
#include <gtest/gtest.h>

#include "rpem/core/estimator.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/sga_kernel.hpp"

namespace rpem::core {
namespace {

void expect_same_trajectory(double n_pu, double torque_pu, Param adapting) {
  EstimatorConfig config = test::paper_config(Algorithm::kSga);
  config.gradient_psi_m = config.gradient_r_s = GradientForm::kDynamic;
  RpemEstimator estimator(config);
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.plant.psi_m_pu *= 0.95;
  gen.plant.r_s_pu *= 1.1;
  gen.omega_n_rad_s = config.omega_n_rad_s;
  gen.n_pu = n_pu;
  gen.i_ref_pu = mtpa_reference(gen.plant, torque_pu);
  gen.current_noise_pu = 0.002;

  // The first sample synchronises both on the measurement, the gradients at their equilibrium.
  const EstimatorSample first = gen.next();
  (void)estimator.step(first);
  test::SgaKernel k = test::SgaKernel::from(config, gen.dt_s);
  k.synchronize(estimator.state().predictor);

  for (int s = 0; s < 20000; ++s) {
    const EstimatorSample sample = gen.next();
    const EstimatorOutput out = estimator.step(sample);
    k.step(sample);
    ASSERT_EQ(out.code, StepCode::kAdapted);
    ASSERT_NEAR(k.psi, out.theta_pu[kPsiM], 1e-12) << "sample " << s;
    ASSERT_NEAR(k.rs, out.theta_pu[kRs], 1e-12) << "sample " << s;
    ASSERT_NEAR(k.id, out.i_hat_pu[0], 1e-12) << "sample " << s;
    ASSERT_NEAR(k.iq, out.i_hat_pu[1], 1e-12) << "sample " << s;
    ASSERT_NEAR(k.grd, out.gradient(0, kRs), 1e-10) << "sample " << s;
  }
  // The adapting parameter has moved towards the plant's, the other has not moved.
  const int j = static_cast<int>(adapting);
  EXPECT_GT(std::abs(estimator.state().theta_pu[j] - config.initial_theta_pu[j]), 1e-3);
  EXPECT_EQ(estimator.state().theta_pu[1 - j], config.initial_theta_pu[1 - j]);
}

TEST(SgaKernel, ComputesWhatTheEstimatorComputesWithPsiMAdapting) { expect_same_trajectory(0.4, 0.4, Param::kPsiM); }

TEST(SgaKernel, ComputesWhatTheEstimatorComputesWithRsAdapting) { expect_same_trajectory(0.005, 0.4, Param::kRs); }

}  // namespace
}  // namespace rpem::core
