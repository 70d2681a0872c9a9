// Closed-loop runs at constant speed and torque against the steady state of the dq equations, and the log's
// semantics (the command of row k held in the stator frame until row k+1) against the plant's applied voltage.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "case_fixtures.hpp"
#include "indep_drive/controller.hpp"
#include "indep_drive/flux_map.hpp"
#include "indep_drive/generator.hpp"

namespace indep {
namespace {

struct Means {
  Vec2 i, u;
  double omega = 0;
};

Means tail_means(const Result& r, std::size_t n) {
  Means m;
  const std::size_t from = r.plant.size() - n;
  for (std::size_t k = from; k < r.plant.size(); ++k) {
    m.i = m.i + r.plant[k].i_A;
    m.u = m.u + r.plant[k].u_applied_V;
    m.omega += r.plant[k].omega_el_rad_s;
  }
  const double w = 1.0 / static_cast<double>(n);
  return {w * m.i, w * m.u, w * m.omega};
}

TEST(IndepSteadyState, LinearMachineOffItsConfigurationMeetsTheDqEquations) {
  Case c = testing::ideal_case();
  // The true machine off the configuration: the controller's feed-forward is wrong.
  c.draw.psi_m_rel = -0.06;
  c.draw.r_s_rel = 0.2;
  c.draw.l_d_rel = 0.04;
  c.draw.l_q_rel = -0.03;
  c.duration_s = 0.8;
  testing::hold(c, 400.0, 20.0);
  const Result r = generate(c);
  const MachineParams& t = r.truth.true_machine;
  ASSERT_DOUBLE_EQ(t.r_s_Ohm, 1.2 * c.machine.params.r_s_Ohm);
  const Means m = tail_means(r, 800);
  // u_d = R·i_d − ω·L_q·i_q,  u_q = R·i_q + ω·(L_d·i_d + ψm)
  const double ud = t.r_s_Ohm * m.i.x - m.omega * t.l_q_H * m.i.y;
  const double uq = t.r_s_Ohm * m.i.y + m.omega * (t.l_d_H * m.i.x + t.psi_m_Wb);
  const double scale = std::hypot(ud, uq);
  EXPECT_NEAR(m.u.x, ud, 2e-4 * scale);
  EXPECT_NEAR(m.u.y, uq, 2e-4 * scale);
  // The PI integrators remove the feed-forward error (the last of it with the slow time constant L_q/R_s ≈ 90 ms
  // that the mismatched zero leaves): the currents are the configured machine's MTPA point.
  const Vec2 ref = mtpa_current(20.0, c.machine.params, 1e3);
  EXPECT_NEAR(m.i.x, ref.x, 5e-4 * ref.norm());
  EXPECT_NEAR(m.i.y, ref.y, 5e-4 * ref.norm());
  // Torque 1.5·p·(ψm·i_q + (L_d − L_q)·i_d·i_q) of the true machine.
  const Vec2 i = r.plant.back().i_A;
  const double torque = 1.5 * t.pole_pairs * (t.psi_m_Wb * i.y + (t.l_d_H - t.l_q_H) * i.x * i.y);
  EXPECT_NEAR(r.plant.back().torque_Nm, torque, 1e-12 * torque);
}

TEST(IndepSteadyState, SaturatedMachineMeetsTheDqEquationsOnItsMap) {
  Case c = testing::ideal_case();
  c.duration_s = 0.8;
  c.effects.saturation = {
      true,  true, true, testing::source_path("data/beckhoff-am8141-flux-maps/beckhoff_AM8141_measured_400rpm.csv"),
      kAuto, 2.5,  4};
  testing::hold(c, -300.0, -25.0);
  const Result r = generate(c);
  const MachineParams& t = r.truth.true_machine;
  const Case& rc = r.resolved;
  const FluxMapFit fit = fit_flux_map(read_flux_map(rc.effects.saturation.map_path));
  const FluxModel f = scale_flux_map(fit, t, rc.effects.saturation.full_scale_current_A, {true, true, true, 2.5});
  const Means m = tail_means(r, 800);
  const Vec2 psi = f.flux(m.i, t.psi_m_Wb);
  // u = R·i + ω·J·ψ(i)
  const double ud = t.r_s_Ohm * m.i.x - m.omega * psi.y;
  const double uq = t.r_s_Ohm * m.i.y + m.omega * psi.x;
  const double scale = std::hypot(ud, uq);
  EXPECT_NEAR(m.u.x, ud, 2e-4 * scale);
  EXPECT_NEAR(m.u.y, uq, 2e-4 * scale);
  // The saturation is there to be seen: ψ_q is well below the linear L_q·i_q.
  EXPECT_LT(std::abs(psi.y), 0.99 * std::abs(t.l_q_H * m.i.y));
}

TEST(IndepLogSemantics, RowKCommandHeldInTheStatorFrameIsTheAppliedVoltage) {
  // Without effects the plant's applied voltage over [t_k, t_k+1) is the logged command held in the stator frame:
  //   ū_dq = (1/T)∫ e^{−jθ(t)}·u_αβ dt = u_αβ·e^{−jθ_k}·(1 − e^{−jωT})/(jωT).
  Case c = testing::ideal_case();
  c.duration_s = 0.3;
  const double rpm = 450.0;
  testing::hold(c, rpm, 15.0);
  const Result r = generate(c);
  const double omega = rpm / 60.0 * 2 * kPi * c.machine.params.pole_pairs, t_c = 1.0 / c.control.rate_Hz;
  using C = std::complex<double>;
  const C factor = (1.0 - std::exp(C(0, -omega * t_c))) / C(0, omega * t_c);
  double worst = 0.0;
  for (std::size_t k = 100; k < r.log.size(); ++k) {
    const Vec2 ab = clarke(r.log[k].u_abc_V);
    const C expected = C(ab.x, ab.y) * std::exp(C(0, -r.plant[k].theta_el_rad)) * factor;
    const Vec2 applied = r.plant[k].u_applied_V;
    worst = std::max(worst, std::abs(C(applied.x, applied.y) - expected) / std::abs(expected));
    // The logged angle is the true one (ideal encoder, no offset).
    ASSERT_NEAR(std::remainder(r.log[k].theta_el_rad - r.plant[k].theta_el_rad, 2 * kPi), 0.0, 1e-9);
  }
  // The plant's average is a trapezoid over RK4 sub-steps h: its error on the turning voltage is (ω·h)²/12 = 1.6e-6.
  EXPECT_LT(worst, 3e-6);
}

}  // namespace
}  // namespace indep
