// The plant on its own: energy balance with dead time, saliency and the shaft; the torque's textbook form; the
// open phases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "indep_vesc/plant.hpp"

namespace indep::vesc {
namespace {

PlantParams salient_machine() {
  PlantParams p;
  p.r_s_Ohm = 0.03;
  p.psi_m_Wb = 0.005;
  p.l_d_H = 18e-6;
  p.l_q_H = 26e-6;
  p.pole_pairs = 7;
  p.inertia_kgm2 = 4e-4;
  p.coulomb_Nm = 0.01;
  p.viscous_Nm_s = 1e-5;
  p.drag_Nm_s2 = 2e-6;
  p.external_Nm = 0.05;
  p.t_dead_s = 0.3e-6;
  p.f_sw_Hz = 12500.0;
  p.dead_band_A = 0.5;
  return p;
}

struct Balance {
  double terminal_error = 0.0, shaft_error = 0.0, scale = 0.0;
};

// ∫1.5·v·i dt = ∫1.5·R·|i|² dt + ΔW_magnetic + ∫T_e·ω_m dt  (terminals), and
// ∫T_e·ω_m dt = ΔE_kinetic + ∫T_load·ω_m dt                   (shaft),
// over 0.2 s of random leg voltages held for 40 µs each (half PWM periods), integrated in `substeps` steps.
Balance energy_balance(int substeps) {
  const Plant plant(salient_machine());
  PlantState x;
  x.theta_el_rad = 0.7;
  x.omega_m_rad_s = 150.0;
  plant.open_phases(x);
  const double w0 = plant.magnetic_energy_J(x), k0 = plant.kinetic_energy_J(x);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> duty(0.2, 0.8);
  const double v_dc = 48.0, hold = 40e-6;
  double in = 0.0, cu = 0.0, shaft = 0.0, load = 0.0;
  for (int k = 0; k < 5000; ++k) {
    const std::array<double, 3> legs{duty(rng) * v_dc, duty(rng) * v_dc, duty(rng) * v_dc};
    for (int s = 0; s < substeps; ++s) {
      const IntervalResult r = plant.step_on(x, hold / substeps, legs, v_dc);
      in += r.energy_in_J;
      cu += r.energy_cu_J;
      shaft += r.energy_shaft_J;
      load += r.energy_load_J;
    }
  }
  Balance b;
  b.terminal_error = (in - cu - shaft) - (plant.magnetic_energy_J(x) - w0);
  b.shaft_error = (shaft - load) - (plant.kinetic_energy_J(x) - k0);
  b.scale = std::fabs(in) + cu + std::fabs(shaft);
  return b;
}

// The balance closes to the integration's order: the stage powers are evaluated on RK4's intermediate states,
// so the energies are second-order accurate in the step (the states fourth-order). The random ±14 V steps every
// 40 µs swing the 20 µH machine's current by tens of amperes within a step.
TEST(IndepVescPlant, EnergyEnteringTheTerminalsIsLossStoredFieldAndShaftWork) {
  const Balance coarse = energy_balance(1), fine = energy_balance(4);
  ASSERT_GT(coarse.scale, 20.0);
  EXPECT_LT(std::fabs(coarse.terminal_error), 5e-5 * coarse.scale);
  EXPECT_LT(std::fabs(fine.terminal_error), 2e-6 * fine.scale);
  EXPECT_LT(std::fabs(fine.terminal_error), 0.1 * std::fabs(coarse.terminal_error)) << "second order: 1/16 at h/4";
  EXPECT_LT(std::fabs(fine.shaft_error), 1e-6 * fine.scale);
}

TEST(IndepVescPlant, TorqueIsTheDqFormWithReluctanceTorque) {
  const PlantParams p = salient_machine();
  const Plant plant(p);
  PlantState x;
  x.theta_el_rad = 1.1;
  const Vec2 i_dq{-3.0, 20.0};
  x.psi_ab_Wb = inverse_park({p.l_d_H * i_dq.x + p.psi_m_Wb, p.l_q_H * i_dq.y}, x.theta_el_rad);
  EXPECT_NEAR(plant.current_dq(x).x, i_dq.x, 1e-9);
  EXPECT_NEAR(plant.current_dq(x).y, i_dq.y, 1e-9);
  const double expected = 1.5 * p.pole_pairs * (p.psi_m_Wb * i_dq.y + (p.l_d_H - p.l_q_H) * i_dq.x * i_dq.y);
  EXPECT_NEAR(plant.torque_Nm(x), expected, 1e-12);
}

TEST(IndepVescPlant, OpenPhasesCarryNoCurrentAndTheBackEmf) {
  const Plant plant(salient_machine());
  PlantState x;
  x.theta_el_rad = -2.0;
  x.omega_m_rad_s = 100.0;
  plant.open_phases(x);
  const IntervalResult r = plant.step_off(x, 40e-6);
  EXPECT_DOUBLE_EQ(plant.current_ab(x).norm(), 0.0);
  EXPECT_NEAR(r.v_dq_mean_V.y, 7 * x.omega_m_rad_s * 0.005, 1e-3 * 3.5);
  EXPECT_DOUBLE_EQ(r.v_dq_mean_V.x, 0.0);
}

}  // namespace
}  // namespace indep::vesc
