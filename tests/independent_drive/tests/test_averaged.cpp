// Averaged rotor-frame mode: uneven contiguous intervals within their bounds, plant averages that meet the
// dq steady state, and drive averages equal to the mean of the controller's own per-cycle values.
#include <gtest/gtest.h>

#include <cmath>

#include "case_fixtures.hpp"
#include "indep_drive/generator.hpp"

namespace indep {
namespace {

TEST(IndepAveraged, IntervalsAreUnevenContiguousAndBounded) {
  for (double rate : {50.0, 200.0, 1000.0}) {
    Case c = testing::machine_case();
    c.duration_s = 2.0;
    c.averaged.on = true;
    c.averaged.rate_Hz = rate;
    c.averaged.jitter_rel = 0.4;
    const Result r = generate(c);
    ASSERT_GT(r.averaged.size(), 10u);
    EXPECT_NEAR(static_cast<double>(r.averaged.size()), 2.0 * rate, 0.1 * 2.0 * rate);
    double shortest = 1.0, longest = 0.0;
    for (std::size_t k = 0; k < r.averaged.size(); ++k) {
      const double dt = r.averaged[k].t_s - r.averaged[k].t_start_s;
      shortest = std::min(shortest, dt);
      longest = std::max(longest, dt);
      ASSERT_GE(dt, std::max(0.5e-3, 0.6 / rate) - 1e-12);
      ASSERT_LE(dt, std::min(20e-3, 1.4 / rate) + 1e-12);
      if (k > 0) {
        ASSERT_EQ(r.averaged[k].t_start_s, r.averaged[k - 1].t_s);
      }
    }
    EXPECT_GT(longest - shortest, 0.3 / rate);
  }
}

TEST(IndepAveraged, PlantAveragesMeetTheSteadyState) {
  Case c = testing::ideal_case();
  c.draw = MachineDraw{};
  c.seed = 5;
  c.duration_s = 1.0;
  c.averaged.on = true;
  c.averaged.rate_Hz = 200.0;
  testing::hold(c, 350.0, 22.0);
  const Result r = generate(c);
  const MachineParams& t = r.truth.true_machine;
  int checked = 0;
  for (const AveragedRow& a : r.averaged) {
    if (a.t_start_s < 0.5) continue;
    const double ud = t.r_s_Ohm * a.i_d_A - a.omega_el_rad_s * t.l_q_H * a.i_q_A;
    const double uq = t.r_s_Ohm * a.i_q_A + a.omega_el_rad_s * (t.l_d_H * a.i_d_A + t.psi_m_Wb);
    ASSERT_NEAR(a.u_d_V, ud, 2e-4 * std::hypot(ud, uq));
    ASSERT_NEAR(a.u_q_V, uq, 2e-4 * std::hypot(ud, uq));
    ASSERT_NEAR(a.u_dc_V, r.resolved.inverter.u_dc_V, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 80);
}

TEST(IndepAveraged, DriveAveragesAreTheMeanOfTheControllersCycles) {
  Case c = testing::machine_case();
  c.duration_s = 0.5;
  c.averaged.on = true;
  c.averaged.rate_Hz = 1000.0;
  c.averaged.source = AveragedSource::drive;
  const Result r = generate(c);
  std::size_t k = 0;
  for (const AveragedRow& a : r.averaged) {
    Vec2 sum;
    double n = 0;
    for (; k < r.log.size() && r.log[k].t_s < a.t_s; ++k) {
      if (r.log[k].t_s < a.t_start_s) continue;
      sum = sum + park(clarke(r.log[k].i_abc_A), r.log[k].theta_el_rad);
      n += 1;
    }
    ASSERT_GT(n, 0);
    ASSERT_NEAR(a.i_d_A, sum.x / n, 1e-9);
    ASSERT_NEAR(a.i_q_A, sum.y / n, 1e-9);
  }
}

}  // namespace
}  // namespace indep
