// The dead-time voltage the closed loop has to make up, against the textbook average: per leg
// e = −ΔV·tanh(i/i_band), ΔV = t_dead·f_sw·u_dc + v_device; its fundamental in the rotor frame is
// −ΔV·c₁·i/|i| with c₁ = (1/π)∫₀^{2π} tanh(Î·cos φ/i_band)·cos φ dφ (→ 4/π for Î ≫ i_band).
#include <gtest/gtest.h>

#include <cmath>

#include "case_fixtures.hpp"
#include "indep_drive/generator.hpp"

namespace indep {
namespace {

/// Mean of the controller's rotor-frame command over the last whole electrical periods of a constant-speed run.
Vec2 mean_command(const Result& r, double omega, double advance) {
  const double t_c = r.truth.control_period_s;
  const auto per_period = 2 * kPi / (omega * t_c);
  const auto n =
      static_cast<std::size_t>(std::llround(std::floor(static_cast<double>(r.log.size()) / 2.0 / per_period) * per_period));
  Vec2 sum;
  for (std::size_t k = r.log.size() - n; k < r.log.size(); ++k) {
    const LogRow& row = r.log[k];
    sum = sum + park(clarke(row.u_abc_V), row.theta_el_rad + omega * t_c * advance);
  }
  return (1.0 / static_cast<double>(n)) * sum;
}

TEST(IndepDeadTime, TheLoopMakesUpTheFundamentalOfTheLegErrors) {
  const double rpm = 300.0, torque = 20.0;
  Case base = testing::ideal_case();
  base.duration_s = 1.0;
  testing::hold(base, rpm, torque);
  Case with = base;
  with.effects.deadtime = {true, 2e-6, 1.0, 0.15};
  const Result a = generate(base), b = generate(with);
  const double omega = rpm / 60 * 2 * kPi * base.machine.params.pole_pairs;
  const Vec2 du = mean_command(b, omega, 0.5) - mean_command(a, omega, 0.5);

  const Case& rc = b.resolved;
  const double dv = 2e-6 * rc.inverter.switching_frequency_Hz * rc.inverter.u_dc_V + 1.0;
  const Vec2 i = b.plant.back().i_A;
  const double amplitude = i.norm();
  double c1 = 0.0;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const double phi = 2 * kPi * (k + 0.5) / n;
    c1 += std::tanh(amplitude * std::cos(phi) / 0.15) * std::cos(phi) * (2 * kPi / n) / kPi;
  }
  EXPECT_NEAR(c1, 4 / kPi, 0.05);
  const Vec2 expected = (dv * c1 / amplitude) * i;  // the command rises by what the legs lose
  EXPECT_NEAR(du.x, expected.x, 0.01 * dv * c1);
  EXPECT_NEAR(du.y, expected.y, 0.01 * dv * c1);
  EXPECT_NEAR(b.truth.effect("deadtime")->value("per_leg_amplitude_V"), dv, 1e-9);
  EXPECT_NEAR(b.truth.effect("deadtime")->value("dq_fundamental_amplitude_V"), 4 / kPi * dv, 1e-9);
}

}  // namespace
}  // namespace indep
