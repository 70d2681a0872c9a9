// The plant against the analytic steady state: a constant rotor-frame voltage (rotated into the
// stator frame step by step) at constant speed settles at core::steady_state_current.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/machine.hpp"
#include "rpem/sim/plant.hpp"
#include "support/paper_plant.hpp"

namespace rpem::sim {
namespace {

core::Vec2 settle(PmsmPlant& plant, const PlantParameters& p, double omega, const core::Vec2& u_dq, double seconds,
                  double h) {
  MechanicsConfig mech;
  plant.reset(core::Vec2::Zero(), 0.3, omega, p);
  const int periods = static_cast<int>(seconds / 125e-6), steps = static_cast<int>(std::lround(125e-6 / h));
  for (int k = 0; k < periods; ++k) {
    plant.begin_period(p, h, 0.0);
    for (int s = 0; s < steps; ++s) {
      // Mean over the step of the rotating stator-frame voltage, as an ideal inverter would supply.
      const double theta_mid = plant.state().theta_el_rad + 0.5 * omega * h;
      const double sinc = std::abs(omega * h) > 0 ? std::sin(0.5 * omega * h) / (0.5 * omega * h) : 1.0;
      plant.step(sinc * core::inverse_park(u_dq, core::Rotation::of(theta_mid)));
    }
  }
  return plant.state().i_A;
}

TEST(Plant, SettlesAtTheAnalyticSteadyState) {
  const PlantParameters p = test::paper_plant_parameters();
  const core::PerUnitBase base = test::paper_base();
  const core::MachinePu m = test::paper_machine_pu();
  for (double n : {0.0, 0.3, -0.8}) {
    PmsmPlant plant(3, Magnetics(), MechanicsConfig{});
    const double omega = n * base.omega_el_rad_s;
    const core::Vec2 i_target(-0.5, 2.0);
    const core::Vec2 u_dq = core::steady_state_voltage(m, n, i_target / base.current_A) * base.voltage_V;
    // 2.5 s ≥ 27 time constants L_q/R_s. Heun's steady-state error scales as (ω·h)²: at 2.5 µs and
    // 0.8 pu, (ω·h)² ≈ 4e-7 of the current.
    const core::Vec2 i = settle(plant, p, omega, u_dq, 2.5, 2.5e-6);
    EXPECT_LT((i - i_target).norm(), 1e-6) << "n=" << n;
    // T = 1.5·p·(ψ_m·i_q + (L_d − L_q)·i_d·i_q)
    const double torque = 1.5 * 3 * (p.psi_m_Wb * i[1] + (p.l_d_H - p.l_q_H) * i[0] * i[1]);
    EXPECT_NEAR(plant.state().torque_Nm, torque, 1e-6);
  }
}

TEST(Plant, IronLossDrawsTheInducedVoltageOverRfe) {
  PlantParameters p = test::paper_plant_parameters();
  p.r_fe_Ohm = 2000.0;
  const core::PerUnitBase base = test::paper_base();
  PmsmPlant plant(3, Magnetics(), MechanicsConfig{});
  const double omega = 0.5 * base.omega_el_rad_s;
  // Magnetising current i_m = (0, 1): ψ = (ψ_m, L_q); stator current = i_m + ω·J·ψ/R_fe.
  const core::Vec2 i_m(0.0, 1.0);
  const core::Vec2 psi(p.psi_m_Wb, p.l_q_H);
  const core::Vec2 i_s = i_m + omega / p.r_fe_Ohm * core::Vec2(-psi[1], psi[0]);
  const core::Vec2 u_dq(p.r_s_Ohm * i_s[0] - omega * psi[1], p.r_s_Ohm * i_s[1] + omega * psi[0]);
  const core::Vec2 i = settle(plant, p, omega, u_dq, 1.0, 1e-6);
  EXPECT_LT((i - i_s).norm(), 1e-6);
}

TEST(Plant, InertiaModeAcceleratesWithTheTorqueDifference) {
  const PlantParameters p = test::paper_plant_parameters();
  MechanicsConfig mech;
  mech.dynamometer = false;
  mech.inertia_kgm2 = 0.02;
  PmsmPlant plant(3, Magnetics(), mech);
  plant.reset(core::Vec2(0.0, 2.0), 0.0, 0.0, p);
  // Hold the current by flux: at standstill u = R·i keeps it.
  plant.begin_period(p, 1e-6, 1.0);
  for (int k = 0; k < 1000; ++k) plant.step(core::inverse_park(core::Vec2(0.0, p.r_s_Ohm * 2.0), plant.rotation()));
  const double torque = 1.5 * 3 * p.psi_m_Wb * 2.0;
  const double expected_omega_el = 3 * (torque - 1.0) / mech.inertia_kgm2 * 1e-3;
  EXPECT_NEAR(plant.state().omega_el_rad_s, expected_omega_el, 0.02 * expected_omega_el);
}

}  // namespace
}  // namespace rpem::sim
