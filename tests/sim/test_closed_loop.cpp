// The simulated drive in closed loop: FOC tracks MTPA, averaged and switching inverters agree in the
// fundamental, field weakening holds the voltage limit, the speed loop settles, temperatures move the
// parameters by their coefficients, and the estimator in the loop tracks a ψm step.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/machine.hpp"
#include "rpem/sim/drive_simulator.hpp"

namespace rpem::sim {
namespace {

Scenario operating_point(double n_pu, double tau_pu, InverterModel model, double u_dc = 565.0) {
  Scenario s = paper_scenario();
  s.inverter.model = model;
  s.plant_step_s = model == InverterModel::kSwitching ? 1e-6 : s.sample_period_s;
  s.signal(Quantity::kSpeed) = Signal(n_pu * 1000.0);
  s.signal(Quantity::kTorque) = Signal(tau_pu * 32.6);
  s.signal(Quantity::kUdc) = Signal(u_dc);
  return s;
}

struct Means {
  core::Vec2 i_dq = core::Vec2::Zero();
  core::Vec2 u_cmd_dq = core::Vec2::Zero();
  double torque = 0.0;
  double u_cmd_max = 0.0;
};

/// Means over the last `tail_s` of the scenario.
Means run(Scenario s, double tail_s) {
  DriveSimulator d(std::move(s));
  io::DriveLogRow row;
  TruthRow truth;
  Means m;
  const auto tail = static_cast<std::int64_t>(tail_s / d.scenario().sample_period_s);
  std::int64_t k = 0;
  while (d.next(row, truth)) {
    if (k++ < d.samples_total() - tail) continue;
    m.i_dq += truth.i_dq_A / static_cast<double>(tail);
    const core::Vec2 u_ab = core::clarke(row.sample.u_V);
    m.u_cmd_dq += core::park(u_ab, core::Rotation::of(truth.theta_el_rad)) / static_cast<double>(tail);
    m.torque += truth.torque_Nm / static_cast<double>(tail);
    m.u_cmd_max = std::max(m.u_cmd_max, u_ab.norm());
  }
  return m;
}

TEST(ClosedLoop, FocTracksTheMtpaReference) {
  for (auto [n, tau] : {std::pair{0.4, 0.2}, {-0.2, 0.6}, {0.8, 0.4}, {0.0, 0.4}}) {
    Scenario s = operating_point(n, tau, InverterModel::kSwitching);
    s.duration_s = 0.3;
    const Means m = run(s, 0.1);
    const core::PerUnitBase b = core::PerUnitBase::from_rated(s.machine.machine.rated);
    const core::Vec2 ref = core::mtpa_reference(core::to_pu(b, s.machine.machine), tau) * b.current_A;
    EXPECT_LT((m.i_dq - ref).norm(), 0.01 * b.current_A) << "n=" << n << " tau=" << tau;
    EXPECT_NEAR(m.torque, tau * 32.6, 0.01 * 32.6);
  }
}

TEST(ClosedLoop, AveragedAndSwitchingInvertersAgreeInTheFundamental) {
  for (double dead_time : {0.0, 2e-6}) {
    Scenario sw = operating_point(0.3, 0.4, InverterModel::kSwitching, 220.0);
    Scenario av = operating_point(0.3, 0.4, InverterModel::kAveraged, 220.0);
    sw.duration_s = av.duration_s = 0.4;
    sw.inverter.dead_time_s = av.inverter.dead_time_s = dead_time;
    const Means a = run(sw, 0.2), b = run(av, 0.2);
    const double i_b = std::sqrt(2.0) * 4.93;
    EXPECT_LT((a.i_dq - b.i_dq).norm(), 0.005 * i_b) << "dead time " << dead_time;
    // The commands (what the controller needed) agree to within 0.5 % of the DC link / √3.
    EXPECT_LT((a.u_cmd_dq - b.u_cmd_dq).norm(), 0.005 * 220.0 / std::sqrt(3.0)) << "dead time " << dead_time;
  }
}

TEST(ClosedLoop, FieldWeakeningHoldsTheVoltageLimit) {
  // 0.5 pu on a 220 V link: the back-EMF (≈ 179 V peak) exceeds u_dc/√3 ≈ 127 V.
  Scenario s = operating_point(0.5, 0.2, InverterModel::kAveraged, 220.0);
  s.duration_s = 1.0;
  const Means m = run(s, 0.2);
  EXPECT_LE(m.u_cmd_max, 220.0 / std::sqrt(3.0) * (1.0 + 1e-9));
  EXPECT_LT(m.i_dq[0], -2.0);  // field-weakening current
  EXPECT_NEAR(m.torque, 0.2 * 32.6, 0.05 * 0.2 * 32.6);
}

TEST(ClosedLoop, SpeedControlSettlesUnderLoad) {
  Scenario s = operating_point(0.0, 0.4, InverterModel::kAveraged, 220.0);
  s.mechanics.dynamometer = false;
  s.mechanics.inertia_kgm2 = 0.02;
  s.control.speed_control = true;
  s.control.inertia_kgm2 = 0.02;
  s.signal(Quantity::kSpeed).add({0.1, EventKind::kRamp, 300.0, 0.2});
  s.duration_s = 2.0;
  DriveSimulator d(s);
  io::DriveLogRow row;
  TruthRow truth;
  while (d.next(row, truth)) {
  }
  EXPECT_NEAR(truth.omega_el_rad_s / 3.0 * 60.0 / (2.0 * core::kPi), 300.0, 3.0);
  EXPECT_NEAR(truth.torque_Nm, 0.4 * 32.6, 0.3);  // the motor carries the load
}

TEST(ClosedLoop, TemperaturesMoveTheParametersByTheirCoefficients) {
  Scenario s = operating_point(0.3, 0.2, InverterModel::kAveraged, 220.0);
  s.signal(Quantity::kTWinding).add({0.0, EventKind::kRamp, 70.0, 0.5});
  s.signal(Quantity::kTMagnet).add({0.0, EventKind::kRamp, 45.0, 0.5});
  s.duration_s = 0.6;
  DriveSimulator d(s);
  io::DriveLogRow row;
  TruthRow truth;
  while (d.next(row, truth)) {
  }
  EXPECT_NEAR(truth.parameters.r_s_Ohm, 2.25 * (1.0 + 0.00393 * 50.0), 1e-12);
  EXPECT_NEAR(truth.parameters.psi_m_Wb, 1.14 * (1.0 - 0.0012 * 25.0), 1e-12);
}

TEST(ClosedLoop, EstimatorInTheLoopTracksAMinusEightPercentPsiStep) {
  Scenario s = operating_point(0.4, 0.2, InverterModel::kSwitching);
  s.sensors.current_noise_A = 0.01;
  s.sensors.current_lsb_A = 0.005;
  s.sensors.encoder_counts = 65536;
  s.signal(Quantity::kPsiM).add({0.5, EventKind::kStep, 0.92 * 1.14, 0.0});
  s.duration_s = 3.5;
  DriveSimulator d(s);
  core::DriveEstimator est(s.machine.machine, s.machine.estimator);
  io::DriveLogRow row;
  TruthRow truth;
  core::Estimate e;
  while (d.next(row, truth)) e = est.step(row.sample);
  EXPECT_NEAR(e.psi_m_Wb / truth.parameters.psi_m_Wb, 1.0, 0.005);
}

}  // namespace
}  // namespace rpem::sim
