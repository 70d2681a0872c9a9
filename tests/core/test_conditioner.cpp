#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rpem/core/conditioner.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

DriveSample sample(std::int64_t t_ns, double theta, const Vec3& u_abc, const Vec3& i_abc) {
  DriveSample s;
  s.t_ns = t_ns;
  s.theta_el_rad = theta;
  s.omega_el_rad_s = 31.4;
  s.u_dc_V = 220.0;
  s.u_V = u_abc;
  s.i_A = i_abc;
  return s;
}

TEST(Conditioner, HeldStatorCommandEntersAtBothEndsOfTheInterval) {
  const PerUnitBase b = test::paper_base();
  SampleConditioner c(b, test::paper_machine_pu(), {});
  const Vec3 u0(100.0, -30.0, -70.0), u1(10.0, 20.0, -30.0), i(1.0, 2.0, -3.0);
  const EstimatorSample first = c.condition(sample(0, 0.3, u0, i));
  EXPECT_TRUE(first.resync);
  const EstimatorSample second = c.condition(sample(125'000, 0.35, u1, i));
  EXPECT_FALSE(second.resync);
  EXPECT_DOUBLE_EQ(second.interval.dt_s, 125e-6);
  const Vec2 u0_ab = clarke(u0) / b.voltage_V;
  EXPECT_LT((second.interval.u_start_pu - park(u0_ab, Rotation::of(0.3))).norm(), 1e-15);
  EXPECT_LT((second.interval.u_end_pu - park(u0_ab, Rotation::of(0.35))).norm(), 1e-15);
  EXPECT_LT((second.i_meas_pu - park(clarke(i), Rotation::of(0.35)) / b.current_A).norm(), 1e-15);
  EXPECT_NEAR(second.interval.n_end_pu, 31.4 / b.omega_el_rad_s, 1e-15);
}

TEST(Conditioner, RotorFrameCommandIsHeldInTheStatorFrame) {
  const PerUnitBase b = test::paper_base();
  SampleConditioner c(b, test::paper_machine_pu(), {});
  DriveSample s0 = sample(0, 1.0, Vec3(50.0, 20.0, 0.0), Vec3(1.0, 0.5, 0.0));
  s0.voltage_frame = Frame::kDq;
  s0.current_frame = Frame::kDq;
  (void)c.condition(s0);
  DriveSample s1 = s0;
  s1.t_ns = 100'000;
  s1.theta_el_rad = 1.2;
  const EstimatorSample out = c.condition(s1);
  EXPECT_LT((out.interval.u_start_pu - Vec2(50.0, 20.0) / b.voltage_V).norm(), 1e-15);
  const Vec2 held = inverse_park(Vec2(50.0, 20.0), Rotation::of(1.0));
  EXPECT_LT((out.interval.u_end_pu - park(held, Rotation::of(1.2)) / b.voltage_V).norm(), 1e-15);
  EXPECT_LT((out.i_meas_pu - Vec2(1.0, 0.5) / b.current_A).norm(), 1e-15);
}

TEST(Conditioner, GapAndNonFiniteInputRestartTheChain) {
  SampleConditioner c(test::paper_base(), test::paper_machine_pu(), {});
  (void)c.condition(sample(0, 0.0, Vec3::Zero(), Vec3::Zero()));
  DriveSample gap = sample(125'000, 0.0, Vec3::Zero(), Vec3::Zero());
  gap.gap_before = true;
  EXPECT_TRUE(c.condition(gap).resync);
  DriveSample bad = sample(250'000, std::nan(""), Vec3::Zero(), Vec3::Zero());
  EXPECT_FALSE(c.condition(bad).i_meas_pu.allFinite());
  EXPECT_TRUE(c.condition(sample(375'000, 0.0, Vec3::Zero(), Vec3::Zero())).resync);
}

TEST(Conditioner, DeadTimeVoltageErrorOpposesEachPhaseCurrent) {
  // Textbook: each leg loses v_err = t_dead·f_sw·u_dc in the direction of its current.
  const PerUnitBase b = test::paper_base();
  ModelExtensions corr;
  corr.deadtime_t_dead_s = 2e-6;
  corr.switching_frequency_Hz = 4000.0;
  SampleConditioner c(b, test::paper_machine_pu(), corr);
  const Vec3 i(2.0, -0.5, -1.5), u(0.0, 0.0, 0.0);
  (void)c.condition(sample(0, 0.0, u, i));
  const EstimatorSample out = c.condition(sample(125'000, 0.0, u, i));
  const double v_err = 2e-6 * 4000.0 * 220.0;  // 1.76 V
  const Vec2 expected = clarke(Vec3(-v_err, v_err, v_err)) / b.voltage_V;
  EXPECT_LT((out.interval.u_start_pu - expected).norm(), 1e-15);
}

TEST(Conditioner, AngleOffsetAndCurrentSensorCorrections) {
  const PerUnitBase b = test::paper_base();
  ModelExtensions corr;
  corr.theta_offset_rad = 0.05;
  corr.current_offset_A = Vec3(0.1, 0.0, 0.0);
  corr.current_gain_error = Vec3(0.0, 0.02, 0.0);
  SampleConditioner c(b, test::paper_machine_pu(), corr);
  const Vec3 i_true(1.0, -0.4, -0.6);
  const Vec3 i_meas(1.0 + 0.1, -0.4 * 1.02, -0.6);
  const EstimatorSample out = c.condition(sample(0, 0.7, Vec3::Zero(), i_meas));
  EXPECT_LT((out.i_meas_pu - park(clarke(i_true), Rotation::of(0.75)) / b.current_A).norm(), 1e-15);
}

TEST(Conditioner, DelayBlendsThePreviousCommandIntoTheInterval) {
  const PerUnitBase b = test::paper_base();
  ModelExtensions corr;
  corr.delay_s = 25e-6;
  SampleConditioner c(b, test::paper_machine_pu(), corr);
  const Vec3 ua(10.0, -5.0, -5.0), ub(-20.0, 10.0, 10.0);
  (void)c.condition(sample(0, 0.0, ua, Vec3::Zero()));
  (void)c.condition(sample(125'000, 0.0, ub, Vec3::Zero()));
  const EstimatorSample out = c.condition(sample(250'000, 0.0, ua, Vec3::Zero()));
  const Vec2 expected = (0.8 * clarke(ub) + 0.2 * clarke(ua)) / b.voltage_V;
  EXPECT_LT((out.interval.u_start_pu - expected).norm(), 1e-15);
}

TEST(Conditioner, RotorFrameLogsTakeTheAngleOffsetAndPhaseCorrectionsToo) {
  // A dq log was made with the logged angle: back to the stator frame with it, forward with the true one.
  const PerUnitBase b = test::paper_base();
  ModelExtensions corr;
  corr.theta_offset_rad = -0.04;
  corr.current_offset_A = Vec3(0.0, 0.2, 0.0);
  SampleConditioner c(b, test::paper_machine_pu(), corr);
  const Rotation logged = Rotation::of(0.9), truth = Rotation::of(0.86);
  const Vec3 i_true(1.5, -0.2, -1.3);
  const Vec2 i_dq_logged = park(clarke(i_true + corr.current_offset_A), logged);
  DriveSample s = sample(0, 0.9, Vec3(30.0, 40.0, 0.0), Vec3(i_dq_logged[0], i_dq_logged[1], 0.0));
  s.voltage_frame = s.current_frame = Frame::kDq;
  const EstimatorSample out = c.condition(s);
  EXPECT_LT((out.i_meas_pu - park(clarke(i_true), truth) / b.current_A).norm(), 1e-14);
  const SteadyStateInputs ss = c.steady_state(s);
  EXPECT_LT((ss.u_pu - park(inverse_park(Vec2(30.0, 40.0), logged), truth) / b.voltage_V).norm(), 1e-14);
}

TEST(Conditioner, SaturationCurvesGiveEachSampleItsInductances) {
  // L(i) = L_nom·(level + curvature·i²) per axis, at the measured axis current.
  const PerUnitBase b = test::paper_base();
  const MachinePu m = test::paper_machine_pu();
  ModelExtensions corr;
  corr.inductance_d = {1.05, 0.0};
  corr.inductance_q = {1.2, -0.004};
  SampleConditioner c(b, m, corr);
  const Vec2 i_dq_A(-2.0, 5.0);
  const Vec3 i_abc = inverse_clarke(inverse_park(i_dq_A, Rotation::of(0.3)));
  const EstimatorSample out = c.condition(sample(0, 0.3, Vec3::Zero(), i_abc));
  EXPECT_NEAR(out.x_d_pu, m.x_d_pu * 1.05, 1e-14);
  EXPECT_NEAR(out.x_q_pu, m.x_q_pu * (1.2 - 0.004 * 25.0), 1e-13);
  SampleConditioner nominal(b, m, {});
  EXPECT_EQ(nominal.condition(sample(0, 0.3, Vec3::Zero(), i_abc)).x_q_pu, 0.0);  // 0: the configured model
}

TEST(Conditioner, IronLossCurrentIsRemovedAndItsResistiveDropToo) {
  // i_s = i_m + n·J·ψ(i_m)/r_fe; the model sees i_m and u − r_s·i_fe (docs/model-extensions.md).
  const PerUnitBase b = test::paper_base();
  const MachinePu m = test::paper_machine_pu();
  ModelExtensions corr;
  corr.iron_loss_r_fe_Ohm = 2000.0;
  SampleConditioner c(b, m, corr);
  const double n = 31.4 / b.omega_el_rad_s, r_fe = 2000.0 / b.impedance_Ohm;
  const Vec2 i_pu(-0.2, 0.5);
  const Vec2 psi(m.x_d_pu * i_pu[0] + m.psi_m_pu, m.x_q_pu * i_pu[1]);
  const Vec2 i_fe = n / r_fe * Vec2(-psi[1], psi[0]);
  DriveSample s = sample(0, 0.0, Vec3(100.0, 50.0, 0.0), Vec3(i_pu[0] * b.current_A, i_pu[1] * b.current_A, 0.0));
  s.voltage_frame = s.current_frame = Frame::kDq;
  const SteadyStateInputs ss = c.steady_state(s);
  EXPECT_LT((ss.i_pu - (i_pu - i_fe)).norm(), 1e-14);
  EXPECT_LT((ss.u_pu - (Vec2(100.0, 50.0) / b.voltage_V - m.r_s_pu * i_fe)).norm(), 1e-14);
}

TEST(Conditioner, SteadyStateDeadTimeIsTheRevolutionAverageOfTheLegErrors) {
  // Independent computation: average the six-step leg errors of balanced currents over one electrical
  // revolution in the rotor frame; its mean is the fundamental −(4/π)·v_err·i/|i|.
  const PerUnitBase b = test::paper_base();
  ModelExtensions corr;
  corr.deadtime_v_err_V = 3.0;
  SampleConditioner c(b, test::paper_machine_pu(), corr);
  const Vec2 i_dq(-1.0, 4.0);
  Vec2 mean = Vec2::Zero();
  constexpr int kSteps = 36000;
  for (int k = 0; k < kSteps; ++k) {
    const Rotation r = Rotation::of(2.0 * kPi * (k + 0.5) / kSteps);
    const Vec3 i_abc = inverse_clarke(inverse_park(i_dq, r));
    Vec3 leg;
    for (int x = 0; x < 3; ++x) leg[x] = i_abc[x] > 0.0 ? -3.0 : 3.0;
    mean += park(clarke(leg), r) / kSteps;
  }
  DriveSample s = sample(0, 1.1, Vec3::Zero(), Vec3(i_dq[0], i_dq[1], 0.0));
  s.voltage_frame = s.current_frame = Frame::kDq;
  EXPECT_LT((c.steady_state(s).u_pu * b.voltage_V - mean).norm(), 2e-3);  // quadrature error of the average
}

TEST(Conditioner, ObservationModelInvertsTheCorrections) {
  // observed(corrected(measurement)) = measurement in the log's frame, for the sensor and angle effects
  // exactly, and for iron loss to first order in i_fe (ψ is evaluated at the other current).
  const PerUnitBase b = test::paper_base();
  ModelExtensions x;
  x.theta_offset_rad = 0.07;
  x.current_offset_A = Vec3(0.1, -0.05, 0.0);
  x.current_gain_error = Vec3(0.0, 0.03, -0.01);
  SampleConditioner c(b, test::paper_machine_pu(), x);
  const Vec3 i_true(2.0, -0.7, -1.3);  // a three-wire machine: no zero sequence
  const DriveSample s =
      sample(0, 2.1, Vec3::Zero(), i_true.cwiseProduct(Vec3::Ones() + x.current_gain_error) + x.current_offset_A);
  const EstimatorSample out = c.condition(s);
  EXPECT_LT((c.observed_current_dq_A(s, out.i_meas_pu) - c.logged_current_dq_A(s)).norm(), 1e-13);
  EXPECT_LT((c.logged_current_dq_A(s) - park(clarke(s.i_A), Rotation::of(2.1))).norm(), 1e-15);
  x.iron_loss_r_fe_Ohm = 3000.0;
  SampleConditioner with_fe(b, test::paper_machine_pu(), x);
  const EstimatorSample fe = with_fe.condition(s);
  const double i_fe_A = (c.logged_current_dq_A(s) - with_fe.observed_current_dq_A(s, out.i_meas_pu)).norm();
  EXPECT_GT(i_fe_A, 1e-3);  // the model current differs by the iron-loss current …
  // … and the round trip errs by i_fe·(the change of ψ it causes)/r_fe ≈ i_fe·|n|·x_q/r_fe.
  const double relative = (31.4 / b.omega_el_rad_s) * test::paper_machine_pu().x_q_pu / (3000.0 / b.impedance_Ohm);
  EXPECT_LT((with_fe.observed_current_dq_A(s, fe.i_meas_pu) - c.logged_current_dq_A(s)).norm(), 2.0 * relative * i_fe_A);
}

TEST(Conditioner, IncrementalRotationAgreesWithTheExactOne) {
  // Consecutive samples rotate by a Taylor-series increment (no libm call) and re-derive exactly every
  // 32 samples; over a long run with encoder-like jitter, speed changes, wraps and a gap the currents it
  // yields must equal the exact Park transform's to 1e-12.
  const PerUnitBase b = test::paper_base();
  SampleConditioner c(b, test::paper_machine_pu(), {});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  double theta = 3.0, worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double omega = k < 10000 ? 300.0 : -620.0;  // up to 0.078 rad per sample, both directions
    theta = wrap_angle(theta + omega * 125e-6 + jitter(rng));
    DriveSample s = sample(k * 125'000LL, theta, Vec3(10.0, -4.0, -6.0), Vec3(1.5, -0.4, -1.1));
    s.gap_before = k == 15000;
    const EstimatorSample out = c.condition(s);
    worst = std::max(worst, (out.i_meas_pu - park(clarke(s.i_A), Rotation::of(theta)) / b.current_A).norm());
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(Conditioner, ReadsTheMachineOnlyWhereTheExtensionsSaySo) {
  // rpem diagnose's replay lets models that differ only in the machine's constants share one conditioner's
  // samples where !reads_machine(): their conditioned samples and observed currents are then equal bit for
  // bit; with an inductance curve or iron loss they are not.
  const PerUnitBase b = test::paper_base();
  const MachinePu m = test::paper_machine_pu();
  MachinePu other = m;
  other.r_s_pu *= 1.1;
  other.psi_m_pu *= 0.9;
  other.x_d_pu *= 1.2;
  other.x_q_pu *= 0.8;
  ModelExtensions x;
  x.theta_offset_rad = 0.05;
  x.current_offset_A = Vec3(0.1, -0.05, 0.0);
  x.deadtime_v_err_V = 2.0;
  x.deadtime_t_dead_s = 1e-6;
  x.switching_frequency_Hz = 8000.0;
  x.delay_s = 60e-6;
  x.flux_harmonics[0].d_cos_Wb = 0.004;
  auto differs = [&](const ModelExtensions& e) {
    SampleConditioner c1(b, m, e), c2(b, other, e);
    bool any = false;
    for (int k = 0; k < 200; ++k) {
      const double theta = wrap_angle(0.05 * k);
      const DriveSample s = sample(k * 125'000LL, theta, Vec3(30.0 * std::cos(theta), 30.0 * std::cos(theta - 2.1), -10.0),
                                   Vec3(2.0 * std::sin(theta), -1.0, 3.0 * std::cos(theta)));
      const EstimatorSample a = c1.condition(s), d = c2.condition(s);
      const Vec2 i_model(0.1, -0.2);
      any = any || a.interval.u_start_pu != d.interval.u_start_pu || a.interval.u_end_pu != d.interval.u_end_pu ||
            a.i_meas_pu != d.i_meas_pu || a.x_d_pu != d.x_d_pu || a.x_q_pu != d.x_q_pu ||
            a.interval.dt_s != d.interval.dt_s ||
            c1.observed_current_dq_A(s, i_model) != c2.observed_current_dq_A(s, i_model);
    }
    return any;
  };
  ASSERT_FALSE(x.reads_machine());
  EXPECT_FALSE(differs(x));
  ModelExtensions curve = x;
  curve.inductance_q = {1.0, -0.004};
  ASSERT_TRUE(curve.reads_machine());
  EXPECT_TRUE(differs(curve));
  ModelExtensions iron = x;
  iron.iron_loss_r_fe_Ohm = 2000.0;
  ASSERT_TRUE(iron.reads_machine());
  EXPECT_TRUE(differs(iron));
}

TEST(DriveEstimator, SiPhaseSamplesConvergeLikeThePerUnitPath) {
  const PerUnitBase base = test::paper_base();
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.plant.psi_m_pu *= 0.92;
  gen.omega_n_rad_s = base.omega_el_rad_s;
  gen.n_pu = -0.4;
  gen.i_ref_pu = mtpa_reference(gen.plant, 0.2);
  DriveEstimator est(test::paper_machine_si(), test::paper_settings());
  std::int64_t t_ns = 0;
  Estimate e;
  for (int k = 0; k < 48000; ++k) e = est.step(gen.next_si(base, t_ns));
  EXPECT_EQ(e.detail.code, StepCode::kAdapted);
  EXPECT_NEAR(e.psi_m_Wb / (0.92 * 1.14), 1.0, 1e-3);
  EXPECT_NEAR(e.r_s_Ohm, 2.25, 1e-12);
  EXPECT_LT(e.epsilon_A.norm(), 1e-3);
}

}  // namespace
}  // namespace rpem::core
