// The integrator: Dormand-Prince 5(4) against exact solutions and against a fine fixed-step reference.
//  - a scalar ODE with a closed-form solution;
//  - the plant where it is linear (standstill with a constant current: copper loss linear in T_w, no other
//    losses, constant coolant), against the exact solution through the eigen-decomposition of the
//    symmetrised network, T(t) = T_ss + C^−½·V·e^{−Λt}·Vᵀ·C^½·(T(0) − T_ss);
//  - the full nonlinear plant on a drive cycle and on a profile with a step, against classical RK4 with a
//    fixed step aligned to the profile's knots. Between knots the plant's right-hand side is continuous but
//    not smooth everywhere: the drive's field weakening has square-root points (where the demanded current
//    reaches the voltage ellipse's edge) and kinks (limits, the air-gap flow regimes), where both methods
//    drop to low order. So: at the default settings the difference to RK4 at 10 ms must stay under a tenth
//    of the logged temperature quantum (0.1 K), what matters to any user of the log; with tight settings
//    (rtol 1e-11, steps ≤ 20 ms) both methods meet within 2e-4 K, twice RK4's own change from 10 to 5 ms
//    on this profile (9e-5 K): they converge to one solution.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures.hpp"
#include "indep_thermal/integrator.hpp"
#include "indep_thermal/network.hpp"
#include "indep_thermal/pi.hpp"

namespace indep_thermal {
namespace {

TEST(IndepThermalIntegrator, ScalarOdeWithinItsTolerance) {
  // y' = −2·t·y, y(0) = 1: y = e^{−t²}.
  for (double tol : {1e-6, 1e-9, 1e-12}) {
    DormandPrince<1> dp({tol, tol, 1.0, -1});
    Eigen::Matrix<double, 1, 1> y;
    y << 1.0;
    double t = 0.0;
    double worst = 0.0;
    for (int k = 1; k <= 30; ++k) {
      dp.advance(
          [](double tt, const Eigen::Matrix<double, 1, 1>& yy) { return Eigen::Matrix<double, 1, 1>(-2.0 * tt * yy(0)); }, t,
          0.1 * k, y);
      worst = std::max(worst, std::abs(y(0) - std::exp(-t * t)));
    }
    EXPECT_EQ(t, 3.0);
    EXPECT_LT(worst, 50.0 * tol) << tol;  // global error: a few times the local tolerance
  }
}

TEST(IndepThermalIntegrator, LinearPlantAgainstExactSolution) {
  const Machine m = test::paderborn_machine();
  Parameters p = draw_parameters(m, 41);
  const double i_q = 180.0;
  const double duration = 3000.0;
  Case c = test::exact_case(m, p, test::constant_profile(0.0, 0.0, i_q, duration), duration, 2.0);
  const Result r = generate(c);

  const Conductances g = conductances(p, 0.0);
  const double k = 1.0 / p.copper_alpha20_per_K - 20.0;
  const double a = 1.5 * p.r_s_ref_Ohm * i_q * i_q / (k + p.r_s_reference_C);
  Eigen::Matrix3d mat = g.matrix();
  mat(0, 0) -= a;
  const double t_c = p.coolant_start_C;
  const Eigen::Vector3d b = Eigen::Vector3d(a * k, 0.0, 0.0) + g.to_coolant() * t_c;
  const Eigen::Vector3d t_ss = mat.partialPivLu().solve(b);
  const Eigen::Vector3d cap = capacities(p);
  const Eigen::Vector3d s = cap.cwiseSqrt();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(s.cwiseInverse().asDiagonal() * mat *
                                                           s.cwiseInverse().asDiagonal());
  const Eigen::Vector3d z0 = eig.eigenvectors().transpose() * (s.asDiagonal() * (Eigen::Vector3d::Constant(t_c) - t_ss));
  double worst = 0.0;
  for (const Row& row : r.rows) {
    const Eigen::Vector3d decay = (-eig.eigenvalues() * row.truth.t_s).array().exp();
    const Eigen::Vector3d exact = t_ss + s.cwiseInverse().asDiagonal() * (eig.eigenvectors() * decay.cwiseProduct(z0));
    worst = std::max(worst, (row.truth.y.head<3>() - exact).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(t_ss(0) - t_c, 30.0);
  EXPECT_LT(worst, 1e-5);  // K, at rtol = atol = 1e-8 (the default)
}

// Classical RK4, fixed step h, knots of the profile and the rows up to `duration` as stops, left limits at each stop.
std::vector<State> rk4_reference(const Plant& plant, double duration, double rate, double h) {
  std::vector<double> stops = plant.profile().knots();
  for (double t = 0.0; t <= duration + 1e-9; t += 1.0 / rate) stops.push_back(t);
  std::sort(stops.begin(), stops.end());
  State y = plant.initial_state();
  std::vector<State> rows = {y};
  double t = 0.0;
  double next_row = 1.0 / rate;
  for (double stop : stops) {
    if (stop > duration + 1e-9) break;  // the profile's knots beyond the simulated part
    if (stop <= t) continue;
    const int n = static_cast<int>(std::ceil((stop - t) / h - 1e-9));
    const double dt = (stop - t) / n;
    auto f = [&](double tt, const State& yy) { return plant.derivative(tt, yy, tt >= stop); };
    for (int i = 0; i < n; ++i) {
      const double t0 = t + i * dt;
      const State k1 = f(t0, y);
      const State k2 = f(t0 + 0.5 * dt, y + 0.5 * dt * k1);
      const State k3 = f(t0 + 0.5 * dt, y + 0.5 * dt * k2);
      const State k4 = f(i == n - 1 ? stop : t0 + dt, y + dt * k3);
      y += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    t = stop;
    if (std::abs(t - next_row) < 1e-9) {
      rows.push_back(y);
      next_row += 1.0 / rate;
    }
  }
  return rows;
}

double worst_difference(const Case& c, double rk4_step_s) {
  const Result r = generate(c);
  const Plant plant(c.machine, c.params, c.profile, c.coolant);
  const std::vector<State> ref = rk4_reference(plant, c.duration_s, c.rate_Hz, rk4_step_s);
  EXPECT_EQ(ref.size(), r.rows.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < std::min(ref.size(), r.rows.size()); ++k) {
    worst = std::max(
        worst, (r.rows[k].truth.y.head<kTemperatureStates>() - ref[k].head<kTemperatureStates>()).cwiseAbs().maxCoeff());
  }
  return worst;
}

/// The drive cycle's simulated part. The sanitizer stage (scripts/test.sh: AddressSanitizer on a -O0 build)
/// runs its first ten minutes: it looks for memory errors, which do not need the whole cycle, and the error
/// against RK4 only accumulates, so the bounds hold on a prefix too; the optimised stage runs all of it.
#if defined(__SANITIZE_ADDRESS__)
constexpr double kDriveCycleSimulated_s = 600.0;
#else
constexpr double kDriveCycleSimulated_s = 1800.0;
#endif

TEST(IndepThermalIntegrator, NonlinearPlantAgainstFineRk4OnADriveCycle) {
  const Machine m = test::paderborn_machine();
  Case c;
  c.machine = m;
  c.params = draw_parameters(m, 42);
  c.profile = drive_cycle_profile(m, 1800.0, 42);
  c.coolant = CoolantMode::loop;
  c.duration_s = kDriveCycleSimulated_s;
  c.rate_Hz = 2.0;
  EXPECT_LT(worst_difference(c, 0.01), 0.01);  // K
  c.control.rtol = c.control.atol = 1e-11;
  c.control.max_step = 0.02;
  EXPECT_LT(worst_difference(c, 0.005), 2e-4);  // K
}

TEST(IndepThermalIntegrator, NonlinearPlantAgainstFineRk4AcrossAStep) {
  const Machine m = test::paper_machine();
  Case c;
  c.machine = m;
  c.params = draw_parameters(m, 43);
  c.profile = heat_cool_profile(m, 1501.0);  // steps at 0.586·1501 = 879.586 s, between rows
  c.coolant = CoolantMode::constant;
  c.duration_s = 1501.0;
  c.rate_Hz = 2.0;
  ASSERT_NE(std::fmod(c.profile.points[3].t_s * 2.0, 1.0), 0.0);
  // i_d given: no field-weakening map, a smooth right-hand side between knots; only the step, at a knot.
  EXPECT_LT(worst_difference(c, 0.01), 1e-5);  // K
}

}  // namespace
}  // namespace indep_thermal
