// Steady state against the analytic solution of the linear network at fixed losses. With the magnet's
// coefficient 0 the iron and rotor losses at a fixed operating point are constants P_s, P_r; the copper loss
// is linear in T_w: P_cu = a·(K + T_w), a = 1.5·R_ref·(1 + k_ac·x²)·|i|²/(K + T_ref). The steady state solves
//   (G − a·e_w·e_wᵀ)·T = (a·K, P_s, P_r) + g_c·T_c
// (solved here with Eigen's LU), which the plant must reach once its slowest mode has decayed below the
// tolerance. With M = G − a·e_w·e_wᵀ and C the capacities, T(t) − T_ss = C^−½·V·e^{−Λt}·Vᵀ·C^½·(T(0) − T_ss)
// (V, Λ of the symmetric C^−½·M·C^−½), so |T(t) − T_ss| ≤ √(C_max/C_min)·e^{−t/τ}·|T(0) − T_ss|, τ = 1/λ_min:
// the run lasts until that bound is a tenth of the tolerance.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures.hpp"
#include "indep_thermal/losses.hpp"
#include "indep_thermal/materials.hpp"
#include "indep_thermal/network.hpp"
#include "indep_thermal/pi.hpp"

namespace indep_thermal {
namespace {

constexpr double kTolerance_K = 1e-6;

/// The linear network at a fixed operating point: M·T = rhs, M = G − a·e_w·e_wᵀ.
struct LinearNetwork {
  Eigen::Matrix3d m;
  Eigen::Vector3d rhs;
};

LinearNetwork linear_network(const Parameters& p, const OperatingPoint& op, double t_c) {
  const double omega_m = op.omega_el_rad_s / p.pole_pairs;
  const Conductances g = conductances(p, omega_m);
  const double k = 1.0 / p.copper_alpha20_per_K - 20.0;
  const double f = std::abs(op.omega_el_rad_s) / (2.0 * kPi);
  const double x = f / p.rated_frequency_Hz;
  const double i2 = op.i_d_A * op.i_d_A + op.i_q_A * op.i_q_A;
  const double a = 1.5 * p.r_s_ref_Ohm * (1.0 + p.ac_factor_at_rated * x * x) * i2 / (k + p.r_s_reference_C);
  const Losses l = compute_losses(p, op, 0.0, 0.0);  // iron and rotor: independent of the temperatures here
  LinearNetwork n{g.matrix(), Eigen::Vector3d(a * k, l.iron(), l.rotor()) + g.to_coolant() * t_c};
  n.m(0, 0) -= a;
  return n;
}

/// The time after which √(C_max/C_min)·e^{−t/τ}·|T(0) − T_ss| is a tenth of the tolerance.
double settling_time_s(const Parameters& p, const LinearNetwork& n, const Eigen::Vector3d& t0, const Eigen::Vector3d& t_ss) {
  const Eigen::Vector3d cap = capacities(p);
  const Eigen::Vector3d s = cap.cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d sym = s.asDiagonal() * n.m * s.asDiagonal();
  const double tau = 1.0 / Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(sym).eigenvalues().minCoeff();
  const double bound = std::sqrt(cap.maxCoeff() / cap.minCoeff()) * (t0 - t_ss).norm();
  return tau * std::log(bound / (0.1 * kTolerance_K));
}

void expect_steady_state(const Machine& m, Parameters p, double speed_rpm, double i_d, double i_q) {
  p.magnet_alpha20_per_K = 0.0;
  const OperatingPoint op{speed_rpm * 2.0 * kPi / 60.0 * p.pole_pairs, i_d, i_q};
  const LinearNetwork n = linear_network(p, op, p.coolant_start_C);
  const Eigen::Vector3d expected = n.m.partialPivLu().solve(n.rhs);
  const Eigen::Vector3d start = Eigen::Vector3d::Constant(p.coolant_start_C + p.initial_rise_K);
  const double duration = settling_time_s(p, n, start, expected);
  const Case c = test::steady_case(m, p, speed_rpm, i_d, i_q, duration, 40.0 / duration);
  const Result r = generate(c);
  const Eigen::Vector3d got = r.rows.back().truth.y.head<3>();
  ASSERT_GT(expected(0) - p.coolant_start_C, 5.0);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(got(i), expected(i), kTolerance_K) << "node " << i << " at " << speed_rpm << " rpm";
  // The sensor's lag has settled on the winding.
  EXPECT_NEAR(r.rows.back().truth.sensor_reading_C, expected(0), kTolerance_K);
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
