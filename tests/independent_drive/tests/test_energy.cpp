// Energy balance of the plant with every machine effect on: what enters at the terminals leaves as copper
// and iron loss and shaft work, or is stored in the field —
//   ∫ 1.5·u·i dt = ∫ 1.5·R·|i|² dt + ∫ P_fe dt + ∫ T·ω/p dt + ΔW_field.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "case_fixtures.hpp"
#include "indep_drive/flux_map.hpp"
#include "indep_drive/integrator.hpp"

namespace indep {
namespace {

TEST(IndepEnergy, TerminalEnergyIsLossesWorkAndStoredField) {
  const MachineParams m{1.2, 2.3, 0.09, 0.2, 3};
  const FluxMapFit fit = fit_flux_map(
      read_flux_map(testing::source_path("data/beckhoff-am8141-flux-maps/beckhoff_AM8141_measured_400rpm.csv")));
  HarmonicFlux h;
  h.add({6, 0.03, 0.4, 0.02, -0.9});
  h.add({12, 0.008, 1.1, 0.005, 0.2});
  const Plant plant(scale_flux_map(fit, m, 7.0, {true, true, true, 2.0}), h, 3000.0, DeadTime{8.0, 0.2}, true);
  const double omega = 120.0;
  auto drivers = [&](double) { return Operating{omega, m.r_s_Ohm, m.psi_m_Wb}; };

  PlantState x;
  x.theta_rad = 0.3;
  x.psi_Wb = plant.flux().flux({}, m.psi_m_Wb) + m.psi_m_Wb * h.value(x.theta_rad);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> volts(-40.0, 40.0);
  std::array<double, 3> legs{};
  PlantEval now = plant.evaluate(x, legs, drivers(0));
  const double w0 = plant.field_energy_J(now, drivers(0));
  double in = 0, copper = 0, iron = 0, work = 0, t = 0;
  auto powers = [&](const PlantState& s, const PlantEval& e) {
    const Operating o = drivers(0);
    return std::array<double, 4>{1.5 * e.u_V.dot(e.i_A), 1.5 * m.r_s_Ohm * e.i_A.dot(e.i_A), plant.iron_loss_W(e),
                                 plant.torque_Nm(s, e, o, m.pole_pairs) * omega / m.pole_pairs};
  };
  const double h_step = 2e-6;
  for (int period = 0; period < 800; ++period) {  // 0.1 s of held leg voltages, 125 µs each: EMF + random
    legs = inverse_clarke(inverse_park({0.0, omega * m.psi_m_Wb}, x.theta_rad));
    for (double& v : legs) v += volts(rng);
    now = plant.evaluate(x, legs, drivers(t));
    for (int j = 0; j < 62; ++j) {
      const std::array<double, 4> p0 = powers(x, now);
      const PlantEval next = rk4_step(plant, x, now, t, h_step, legs, drivers);
      const std::array<double, 4> p1 = powers(x, next);
      in += 0.5 * h_step * (p0[0] + p1[0]);
      copper += 0.5 * h_step * (p0[1] + p1[1]);
      iron += 0.5 * h_step * (p0[2] + p1[2]);
      work += 0.5 * h_step * (p0[3] + p1[3]);
      now = next;
      t += h_step;
    }
  }
  const double stored = plant.field_energy_J(now, drivers(t)) - w0;
  ASSERT_GT(iron, 0.0);
  ASSERT_GT(std::abs(work), 0.0);
  const double scale = std::abs(in) + copper + iron + std::abs(work);
  EXPECT_NEAR(in - copper - iron - work, stored, 1e-5 * scale)
      << "in " << in << " copper " << copper << " iron " << iron << " work " << work << " stored " << stored;
}

TEST(IndepEnergy, LinearTorqueIsTheTextbookForm) {
  const MachineParams m{1.1, 2.0, 0.1, 0.2, 3};
  const Plant plant(FluxModel(m.l_d_H, m.l_q_H, 7.0, {}), HarmonicFlux{}, std::numeric_limits<double>::infinity(), {},
                    false);
  PlantState x;
  const Vec2 i{-2.0, 4.0};
  x.psi_Wb = plant.flux().flux(i, m.psi_m_Wb);
  const Operating o{100.0, m.r_s_Ohm, m.psi_m_Wb};
  const PlantEval e = plant.evaluate(x, {}, o);
  EXPECT_NEAR(e.i_A.x, i.x, 1e-12);
  EXPECT_NEAR(plant.torque_Nm(x, e, o, 3), 1.5 * 3 * (1.1 * 4.0 + (0.1 - 0.2) * -2.0 * 4.0), 1e-12);
}

}  // namespace
}  // namespace indep
