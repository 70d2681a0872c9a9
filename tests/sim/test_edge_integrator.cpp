// Edge-to-edge integration against independent computations: one interval of LinearFlow against
// Eigen's matrix exponential (Padé, scaling and squaring) of the augmented system; MapFlow on a map
// of constant inductances against LinearFlow; the dead time's textbook volt-seconds over a carrier
// period from the flux the integrator moved; zero-current clamping during blanking.
#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>

#include "rpem/sim/edge_integrator.hpp"
#include "support/paper_plant.hpp"

namespace rpem::sim {
namespace {

using Mat5 = Eigen::Matrix<double, 5, 5>;
using Vec5 = Eigen::Matrix<double, 5, 1>;

/// ψ(t) from the augmented system d/dt [ψ; u; 1] = [A I c; 0 Ω 0; 0 0 0]·[ψ; u; 1] (docs/derivations.md
/// §10), its matrix set up here from the plant's equations and exponentiated by Eigen.
core::Vec2 augmented_exponential(const PlantParameters& p, double omega, const core::Vec2& psi0, const core::Vec2& u0,
                                 double t) {
  const double g = p.r_fe_Ohm > 0.0 ? omega / p.r_fe_Ohm : 0.0;
  core::Mat2 j, k;
  j << 0.0, -1.0, 1.0, 0.0;
  k << 1.0 / p.l_d_H, 0.0, 0.0, 1.0 / p.l_q_H;
  k += g * j;
  Mat5 m = Mat5::Zero();
  m.block<2, 2>(0, 0) = -p.r_s_Ohm * k - omega * j;  // dψ/dt = u − R_s·(K·ψ − L⁻¹·ψ_m·e_d) − ω·J·ψ
  m.block<2, 2>(0, 2) = core::Mat2::Identity();
  m.block<2, 1>(0, 4) = core::Vec2(p.r_s_Ohm * p.psi_m_Wb / p.l_d_H, 0.0);
  m.block<2, 2>(2, 2) = -omega * j;  // the stator voltage seen from the rotor turns backwards
  Vec5 z0;
  z0 << psi0, u0, 1.0;
  const Vec5 z = (m * t).exp() * z0;
  return z.head<2>();
}

TEST(LinearFlow, EqualsTheMatrixExponentialOfTheAugmentedSystem) {
  for (const double r_fe : {0.0, 800.0}) {
    for (const double omega : {0.0, 120.0, -600.0, 4000.0}) {
      PlantParameters p = test::paper_plant_parameters();
      p.r_fe_Ohm = r_fe;
      PmsmPlant plant(3, Magnetics(), MechanicsConfig{});
      plant.reset(core::Vec2(-1.5, 4.0), 0.7, omega, p);
      plant.begin_period(p, 125e-6, 0.0);
      LinearFlow flow;
      flow.prepare(plant);
      const core::Vec2 u_ab(250.0, -410.0);
      flow.start(plant, u_ab, 125e-6);
      const core::Vec2 u0 = core::park(u_ab, plant.rotation());
      for (const double t : {0.0, 1e-7, 3.3e-6, 40e-6, flow.reach_s()}) {
        const core::Vec2 expected = augmented_exponential(p, omega, plant.state().psi_Wb, u0, t);
        EXPECT_LT((flow.flux(t) - expected).norm(), 1e-13 * (1.0 + expected.norm()))
            << "omega " << omega << " r_fe " << r_fe << " t " << t;
      }
      // At 4000 rad/s, ρ = μ·h > 1 over 125 µs: the interval is cut to ρ = 1.
      if (omega == 4000.0) {
        EXPECT_LT(flow.reach_s(), 125e-6);
      } else {
        EXPECT_DOUBLE_EQ(flow.reach_s(), 125e-6);
      }
    }
  }
}

TEST(LinearFlow, PhaseCurrentRatesAreTheDerivativesOfThePhaseCurrents) {
  PlantParameters p = test::paper_plant_parameters();
  p.r_fe_Ohm = 900.0;
  PmsmPlant plant(3, Magnetics(), MechanicsConfig{});
  plant.reset(core::Vec2(-1.0, 3.0), 2.1, 300.0, p);
  plant.begin_period(p, 125e-6, 0.0);
  LinearFlow flow;
  flow.prepare(plant);
  flow.start(plant, core::Vec2(-100.0, 300.0), 100e-6);
  const double dt = 1e-9;
  for (const double t : {1e-6, 50e-6, 99e-6}) {
    const core::Vec3 central = (flow.phases(t + dt).i_A - flow.phases(t - dt).i_A) / (2.0 * dt);
    EXPECT_LT((flow.phases(t).rate_A_s - central).norm(), 1e-5 * central.norm()) << t;
  }
  // The start reproduces the plant's own phase currents.
  EXPECT_LT((flow.phases(0.0).i_A - plant.phase_currents()).norm(), 1e-13);
}

/// The paper machine's constant inductances as a flux map on a grid (bilinear interpolation is exact
/// for them), with a deliberately uneven spacing.
std::shared_ptr<const FluxMap> linear_map(const PlantParameters& p) {
  const std::vector<double> d = {-12.0, -7.0, -3.5, -1.0, 0.0, 2.0, 6.0, 12.0};
  const std::vector<double> q = {-12.0, -5.0, -2.0, 0.0, 1.0, 4.5, 12.0};
  std::vector<double> psi_d, psi_q;
  for (const double iq : q) {
    for (const double id : d) {
      psi_d.push_back(p.l_d_H * id + p.psi_m_Wb);
      psi_q.push_back(p.l_q_H * iq);
    }
  }
  return std::make_shared<const FluxMap>(d, q, psi_d, psi_q);
}

TEST(MapFlow, OnAMapOfConstantInductancesAgreesWithTheExactSolutionWithinItsTolerance) {
  const PlantParameters p = test::paper_plant_parameters();
  for (const double tolerance : {1e-7, 1e-9, 1e-11}) {
    PmsmPlant exact(3, Magnetics(), MechanicsConfig{}), mapped(3, Magnetics(linear_map(p)), MechanicsConfig{});
    for (PmsmPlant* plant : {&exact, &mapped}) {
      plant->reset(core::Vec2(-2.0, 5.0), 0.4, 250.0, p);
      plant->begin_period(p, 125e-6, 0.0);
    }
    LinearFlow linear;
    MapFlow map(tolerance);
    linear.prepare(exact);
    map.prepare(mapped);
    // Five intervals of one period, the voltages of a PWM pattern.
    for (const core::Vec2& u :
         {core::Vec2(0, 0), core::Vec2(377, 0), core::Vec2(188, 326), core::Vec2(0, 0), core::Vec2(-188, 326)}) {
      linear.start(exact, u, 25e-6);
      map.start(mapped, u, 25e-6);
      ASSERT_DOUBLE_EQ(map.reach_s(), 25e-6);
      linear.commit(exact, 25e-6);
      map.commit(mapped, 25e-6);
    }
    const double error = (mapped.state().psi_Wb - exact.state().psi_Wb).norm();
    // Five intervals' local errors, each within tolerance × (ψ_m + |ψ|) per step, a few steps each.
    EXPECT_LT(error, 50.0 * tolerance * 2.0 * p.psi_m_Wb) << tolerance;
    EXPECT_LT((mapped.state().i_A - exact.state().i_A).norm(), 1e-3 * std::sqrt(tolerance)) << tolerance;
  }
}

/// Integrates one carrier period (rising, then falling half) at standstill and returns the mean αβ
/// voltage from the flux the integrator moved: with ω = 0 and R_s ≈ 0, Δψ = ∫u dt.
core::Vec2 carrier_period_mean_voltage(const InverterConfig& c, const Duties& d, const core::Vec3& i_abc, double u_dc) {
  PlantParameters p = test::paper_plant_parameters();
  p.r_s_Ohm = 1e-9;
  p.l_d_H = p.l_q_H = 50.0;  // the currents barely move: no zero crossing
  PmsmPlant plant(3, Magnetics(), MechanicsConfig{});
  const core::Vec2 i_dq = core::clarke(i_abc);  // at ϑ = 0 the rotor frame is the stator frame
  plant.reset(i_dq, 0.0, 0.0, p);
  const core::Vec2 psi0 = plant.state().psi_Wb;
  EdgeIntegrator edges(c, 1e-9);
  const double half = 0.5 / c.switching_frequency_Hz;
  for (const bool rising : {true, false}) {
    plant.begin_period(p, half, 0.0);
    edges.integrate(plant, rising, d, u_dc);
  }
  return (plant.state().psi_Wb - psi0) / (2.0 * half);
}

TEST(EdgeIntegrator, DeadTimeAndDeviceDropsGiveTheTextbookVoltSeconds) {
  // As Inverter.DeadTimeProducesTheTextbookVoltageError and .DeviceDropsFollowTheConductingDevice,
  // here from the flux that edge-to-edge integration moves.
  InverterConfig c;
  c.dead_time_s = 3e-6;
  c.v_igbt_V = 1.2;
  c.v_diode_V = 0.8;
  const double u_dc = 220.0, v_err = c.dead_time_s * c.switching_frequency_Hz * u_dc;
  Duties d;
  d.d = {0.6, 0.45, 0.3};
  const core::Vec3 i(2.0, -0.5, -1.5);
  const core::Vec2 mean = carrier_period_mean_voltage(c, d, i, u_dc);
  // Mean leg voltage: d·high + (1 − d)·low with the conducting device's drop, moved by the dead time.
  const core::Vec3 legs(d.d[0] * (u_dc - 1.2) + (1 - d.d[0]) * -0.8 - v_err * (u_dc - 1.2 + 0.8) / u_dc,
                        d.d[1] * (u_dc + 0.8) + (1 - d.d[1]) * 1.2 + v_err * (u_dc + 0.8 - 1.2) / u_dc,
                        d.d[2] * (u_dc + 0.8) + (1 - d.d[2]) * 1.2 + v_err * (u_dc + 0.8 - 1.2) / u_dc);
  EXPECT_LT((mean - core::clarke(legs)).norm(), 1e-7);
}

TEST(EdgeIntegrator, ACurrentReachingZeroDuringBlankingStaysThereUntilTheLegSwitches) {
  // Standstill, all legs switching together at 123 µs with 2 µs of dead time to the half period's end:
  // a zero vector, then blanking with i_a > 0 (leg a low through its lower diode), i_b > 0 (low),
  // i_c < 0 (high through its upper diode). That pulls i_a to zero about 1 µs into the blanking;
  // there both diodes of leg a block and i_a stays at zero to the end.
  InverterConfig c;
  c.dead_time_s = 2e-6;
  PlantParameters p = test::paper_plant_parameters();
  PmsmPlant plant(3, Magnetics(), MechanicsConfig{}), reference(3, Magnetics(), MechanicsConfig{});
  const core::Vec3 i0(0.002, 0.5, -0.502);
  for (PmsmPlant* pl : {&plant, &reference}) {
    pl->reset(core::clarke(i0), 0.0, 0.0, p);
    pl->begin_period(p, 125e-6, 0.0);
  }
  Duties d;
  d.d = core::Vec3::Constant(123e-6 / 125e-6);
  EdgeIntegrator edges(c, 1e-9);
  edges.integrate(plant, true, d, 565.0);
  EXPECT_EQ(edges.counters().zero_crossings, 1);
  EXPECT_GE(edges.counters().clamped_intervals, 1);
  EXPECT_LT(std::abs(plant.phase_currents()[0]), 1e-9);

  // A 1 ns fixed step chatters about zero instead (the current's sign flips the leg every step); its
  // other phases agree to the chatter's size.
  const Inverter inverter(c);
  reference.begin_period(p, 1e-9, 0.0);
  for (int k = 0; k < 125000; ++k) {
    reference.step(inverter.mean_voltage(true, k * 1e-9, 1e-9, d, reference.phase_currents(), 565.0));
  }
  EXPECT_LT(std::abs(reference.phase_currents()[0]), 2e-5);
  EXPECT_LT((reference.phase_currents() - plant.phase_currents()).norm(), 2e-5);
}

TEST(EdgeIntegrator, AnEdgeWithinAPicosecondOfTheStartStillEndsTheHalfPeriod) {
  // Duties within 1e-8 of 1 put the falling half's PWM edge 1e-12 s after its start (a hang once, for
  // the flux map: an interval shorter than the integrator's smallest step).
  const PlantParameters p = test::paper_plant_parameters();
  for (const bool map : {false, true}) {
    PmsmPlant plant(3, map ? Magnetics(linear_map(p)) : Magnetics(), MechanicsConfig{});
    plant.reset(core::Vec2(-1.0, 3.0), 0.0, 200.0, p);
    InverterConfig c;
    c.dead_time_s = 1e-6;
    EdgeIntegrator edges(c, 1e-9);
    Duties d;
    d.d = {1.0 - 8e-9, 0.5, 0.3};
    for (const bool rising : {true, false}) {
      plant.begin_period(p, 125e-6, 0.0);
      edges.integrate(plant, rising, d, 300.0);
    }
    EXPECT_NEAR(plant.state().theta_el_rad, 200.0 * 250e-6, 1e-12) << map;
    EXPECT_EQ(edges.counters().half_periods, 2);
  }
}

}  // namespace
}  // namespace rpem::sim
