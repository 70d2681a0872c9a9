// Steady state against the analytic solution of the linear network at fixed losses. With the magnet's
// coefficient 0 the iron and rotor losses at a fixed operating point are constants P_s, P_r; the copper loss
// is linear in T_w: P_cu = a·(K + T_w), a = 1.5·R_ref·(1 + k_ac·x²)·|i|²/(K + T_ref). The steady state solves
//   (G − a·e_w·e_wᵀ)·T = (a·K, P_s, P_r) + g_c·T_c
// (solved here with Eigen's LU), which the plant must reach after many of its slowest time constants.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures.hpp"
#include "indep_thermal/losses.hpp"
#include "indep_thermal/materials.hpp"
#include "indep_thermal/network.hpp"

namespace indep_thermal {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d analytic_steady_state(const Parameters& p, const OperatingPoint& op, double t_c) {
  const double omega_m = op.omega_el_rad_s / p.pole_pairs;
  const Conductances g = conductances(p, omega_m);
  const double k = 1.0 / p.copper_alpha20_per_K - 20.0;
  const double f = std::abs(op.omega_el_rad_s) / (2.0 * kPi);
  const double x = f / p.rated_frequency_Hz;
  const double i2 = op.i_d_A * op.i_d_A + op.i_q_A * op.i_q_A;
  const double a = 1.5 * p.r_s_ref_Ohm * (1.0 + p.ac_factor_at_rated * x * x) * i2 / (k + p.r_s_reference_C);
  const Losses l = compute_losses(p, op, 0.0, 0.0);  // iron and rotor: independent of the temperatures here
  Eigen::Matrix3d m = g.matrix();
  m(0, 0) -= a;
  const Eigen::Vector3d rhs = Eigen::Vector3d(a * k, l.iron(), l.rotor()) + g.to_coolant() * t_c;
  return m.partialPivLu().solve(rhs);
}

double slowest_time_constant_s(const Parameters& p, double omega_m) {
  const Eigen::Vector3d s = capacities(p).cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d m = s.asDiagonal() * conductances(p, omega_m).matrix() * s.asDiagonal();
  return 1.0 / Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues().minCoeff();
}

void expect_steady_state(const Machine& m, Parameters p, double speed_rpm, double i_d, double i_q) {
  p.magnet_alpha20_per_K = 0.0;
  const OperatingPoint op{speed_rpm * 2.0 * kPi / 60.0 * p.pole_pairs, i_d, i_q};
  const double tau = slowest_time_constant_s(p, op.omega_el_rad_s / p.pole_pairs);
  const double duration = 40.0 * tau;  // e^−40: the initial deviation has gone
  Case c = test::exact_case(m, p, test::constant_profile(speed_rpm, i_d, i_q, duration), duration, 1.0 / tau);
  const Result r = generate(c);
  const Eigen::Vector3d expected = analytic_steady_state(p, op, p.coolant_start_C);
  const Eigen::Vector3d got = r.rows.back().truth.y.head<3>();
  ASSERT_GT(expected(0) - p.coolant_start_C, 5.0);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got(i), expected(i), 1e-6) << "node " << i << " at " << speed_rpm << " rpm";
  // The sensor's lag has settled on the winding.
  EXPECT_NEAR(r.rows.back().truth.sensor_reading_C, expected(0), 1e-6);
}

TEST(IndepThermalSteadyState, StandstillWithCurrent) {
  const Machine m = test::paderborn_machine();
  expect_steady_state(m, draw_parameters(m, 31), 0.0, 0.0, 150.0);
}

TEST(IndepThermalSteadyState, AtSpeedWithIronRotorAndMechanicalLosses) {
  const Machine m = test::paderborn_machine();
  expect_steady_state(m, draw_parameters(m, 32), 5500.0, -200.0, 66.0);
  const Machine paper = test::paper_machine();
  expect_steady_state(paper, draw_parameters(paper, 33), 800.0, -1.0, 4.0);
}

}  // namespace
}  // namespace indep_thermal
