// Energy balance: what the nodes store plus what went into the coolant equals the losses.
//  1. Exactly (to rounding) for the integrator's own accumulators: Σ C_i·ΔT_i − (∫P − ∫Q_c) is a linear
//     invariant of the ODE (plant.hpp), which Runge-Kutta methods keep.
//  2. Independently of them: the losses and the coolant heat of the truth rows integrated by the trapezoid
//     rule, against the stored heat from the row temperatures. The trapezoid's error is estimated by
//     Richardson's rule from the same rows at half the rate; the tolerance, |E_2h − E_h|, is three times that
//     estimate for the rule's order 2. The order holds because the integrand is smooth within every interval
//     of the coarse rows: the profile's knots (where it bends) lie on them, it has no steps (a row takes the
//     value after a step, which no quadrature of rows can place), and it gives i_d, so the drive's
//     field-weakening map, with its square-root points between knots (electrical.hpp), is not in it. It
//     ramps speed and currents, holds, and stands still with current, with the coolant loop on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "fixtures.hpp"
#include "indep_thermal/network.hpp"

namespace indep_thermal {
namespace {

struct Quadrature {
  double fine = 0.0;    // trapezoid over every row
  double coarse = 0.0;  // over every other row
};

template <class F>
Quadrature trapezoid(const Result& r, F&& value) {
  Quadrature q;
  for (std::size_t k = 1; k < r.rows.size(); ++k) {
    const double h = r.rows[k].truth.t_s - r.rows[k - 1].truth.t_s;
    q.fine += 0.5 * h * (value(r.rows[k]) + value(r.rows[k - 1]));
  }
  for (std::size_t k = 2; k < r.rows.size(); k += 2) {
    const double h = r.rows[k].truth.t_s - r.rows[k - 2].truth.t_s;
    q.coarse += 0.5 * h * (value(r.rows[k]) + value(r.rows[k - 2]));
  }
  return q;
}

Case drive_cycle_case(std::uint64_t seed, double duration_s, double rate_Hz) {
  const Machine m = test::paderborn_machine();
  Case c;
  c.machine = m;
  c.params = draw_parameters(m, seed);
  c.profile = drive_cycle_profile(m, duration_s, seed);
  c.coolant = CoolantMode::loop;
  c.duration_s = duration_s;
  c.rate_Hz = rate_Hz;
  c.seed = seed;
  return c;
}

TEST(IndepThermalEnergy, AccumulatorsBalanceToRounding) {
  const Case c = drive_cycle_case(21, 7200, 2);
  const Result r = generate(c);
  const double losses = r.rows.back().truth.y(kEWinding) + r.rows.back().truth.y(kEIron) + r.rows.back().truth.y(kERotor);
  ASSERT_GT(losses, 1e6);
  // Rounding: ~1e-16 relative per operation on energies of this size, over ~3e4 steps.
  EXPECT_LT(r.summary.max_abs_residual_J, 1e-11 * losses);
}

// A 20 Hz run of the profile described above (speed [rpm], i_q, i_d [A]).
Case smooth_case(std::uint64_t seed) {
  Case c = drive_cycle_case(seed, 3600, 20);
  c.profile.gives_i_d = true;
  c.profile.points = {{0, 0, 0, 0},          {20, 0, 100, -20},    {200, 0, 100, -20},    {220, 4000, 60, -120},
                      {900, 4000, 60, -120}, {910, 4000, 20, -80}, {1500, 5500, 20, -80}, {1800, 0, 150, 0},
                      {2400, 0, 150, 0},     {2410, 0, 0, 0},      {3600, 0, 0, 0}};
  return c;
}

TEST(IndepThermalEnergy, StoredPlusCoolantHeatEqualsLossesByIndependentQuadrature) {
  const Case c = smooth_case(22);
  const Result r = generate(c);
  const Eigen::Vector3d cap = capacities(c.params);
  const Row& first = r.rows.front();
  const Row& last = r.rows.back();
  const double stored = cap.dot(last.truth.y.head<3>() - first.truth.y.head<3>());
  const Quadrature losses = trapezoid(r, [](const Row& row) { return row.truth.losses.total(); });
  const Quadrature to_coolant = trapezoid(r, [](const Row& row) { return row.truth.heat_to_coolant_W; });
  const double tol_losses = std::abs(losses.coarse - losses.fine);
  const double tol_coolant = std::abs(to_coolant.coarse - to_coolant.fine);
  ASSERT_GT(losses.fine, 1e6);
  EXPECT_NEAR(losses.fine - to_coolant.fine, stored, tol_losses + tol_coolant + 1e-9 * losses.fine);
  // The accumulators agree with the quadrature within the same bounds.
  EXPECT_NEAR(last.truth.y(kEWinding) + last.truth.y(kEIron) + last.truth.y(kERotor), losses.fine,
              tol_losses + 1e-9 * losses.fine);
  EXPECT_NEAR(last.truth.y(kECoolant), to_coolant.fine, tol_coolant + 1e-9 * to_coolant.fine);
  // The bounds are tight enough to mean something: under 1e-5 of the energy moved.
  EXPECT_LT(tol_losses + tol_coolant, 1e-5 * losses.fine);
  std::printf("losses %.6g J, to coolant %.6g J, stored %.6g J, mismatch %.3g J, tolerance %.3g J\n", losses.fine,
              to_coolant.fine, stored, losses.fine - to_coolant.fine - stored, tol_losses + tol_coolant);
}

TEST(IndepThermalEnergy, CoolantLoopBalance) {
  // The loop's own balance: C_loop·ΔT_c = ∫(Q_c + P_other − G_rad·(T_c − T_amb)) dt, by the trapezoid.
  const Case c = smooth_case(23);
  const Result r = generate(c);
  const Parameters& p = c.params;
  const Quadrature in = trapezoid(r, [&](const Row& row) {
    return row.truth.heat_to_coolant_W + row.truth.other_heat_W -
           p.coolant_radiator_W_K * (row.truth.y(kTCoolant) - p.coolant_start_C);
  });
  const double stored = p.coolant_loop_capacity_J_K * (r.rows.back().truth.y(kTCoolant) - r.rows.front().truth.y(kTCoolant));
  EXPECT_GT(std::abs(stored), 1e4);
  EXPECT_NEAR(in.fine, stored, std::abs(in.coarse - in.fine) + 1e-9 * std::abs(stored));
}

}  // namespace
}  // namespace indep_thermal
