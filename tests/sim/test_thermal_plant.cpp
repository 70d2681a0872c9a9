// The loss-driven thermal plant (sim/thermal_plant.hpp): the trapezoidal steps against the network's exact
// solution (its modes, from a symmetric eigenproblem), its steady state and its energy balance; the loss forms
// at stated points; and in the simulated drive, the winding heated by the copper loss the truth shows, the
// iron by Steinmetz's loss at the magnet's flux, the plant's R_s at the winding's temperature.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

#include "rpem/sim/drive_simulator.hpp"
#include "rpem/sim/thermal_plant.hpp"

namespace rpem::sim {
namespace {

const core::PerUnitBase kBase = core::PerUnitBase::from_rated({400.0, 4.93, 1000.0, 3});

/// The network's conductance matrix at speed ω, written out from the header's three equations.
Eigen::Matrix3d conductances(const ThermalPlantConfig& c, double g_gap) {
  Eigen::Matrix3d g;
  g << c.winding_iron_W_K, -c.winding_iron_W_K, 0.0, -c.winding_iron_W_K, c.winding_iron_W_K + c.iron_coolant_W_K + g_gap,
      -g_gap, 0.0, -g_gap, g_gap + c.magnet_coolant_W_K;
  return g;
}

/// T(t) = T_ss + C^{-1/2}·V·e^{−Λt}·Vᵀ·C^{1/2}·(T0 − T_ss): the modes of C^{-1/2}·G·C^{-1/2} (symmetric).
Eigen::Vector3d exact(const ThermalPlantConfig& c, const ThermalLosses& p, double g_gap, double t_s) {
  const Eigen::Matrix3d g = conductances(c, g_gap);
  const Eigen::Vector3d cap(c.winding_J_K, c.iron_J_K, c.magnet_J_K);
  const Eigen::Vector3d q(p.copper_W, p.iron_W + c.iron_coolant_W_K * c.coolant_C,
                          p.magnet_W + c.magnet_coolant_W_K * c.coolant_C);
  const Eigen::Vector3d steady = g.partialPivLu().solve(q);
  const Eigen::Vector3d s = cap.cwiseSqrt();
  const Eigen::Matrix3d sym = s.cwiseInverse().asDiagonal() * g * s.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sym);
  const Eigen::Vector3d start(c.start_temperature_C(0), c.start_temperature_C(1), c.start_temperature_C(2));
  const Eigen::Vector3d decay = (-eig.eigenvalues() * t_s).array().exp();
  const Eigen::Vector3d modes = eig.eigenvectors().transpose() * s.cwiseProduct(start - steady);
  return steady + s.cwiseInverse().cwiseProduct(eig.eigenvectors() * decay.cwiseProduct(modes));
}

ThermalPlantConfig warm_start() {
  ThermalPlantConfig c;
  c.coolant_C = 30.0;
  c.start_C = {70.0, 45.0, 55.0};
  return c;
}

TEST(ThermalPlant, TrapezoidalStepsFollowTheExactSolution) {
  // 20 minutes of constant losses at half base speed from a warm start. The rule's error is O(h²/τ²):
  // with h = 1 s against the fastest mode's τ ≈ 70 s, a few mK; with h = 0.05 s, 400 times less.
  const ThermalPlantConfig c = warm_start();
  const ThermalLosses p{150.0, 60.0, 4.0};
  const double omega = 0.5 * kBase.omega_el_rad_s;
  for (const auto& [h, tolerance_K] : {std::pair{1.0, 5e-3}, {0.05, 2e-5}}) {
    ThermalPlant plant(c, kBase);
    const auto n = static_cast<int>(std::lround(1200.0 / h));
    for (int k = 0; k < n; ++k) plant.step(p, omega, h);
    const Eigen::Vector3d want = exact(c, p, plant.gap_conductance_W_K(omega), 1200.0);
    EXPECT_NEAR(plant.winding_C(), want(0), tolerance_K) << h;
    EXPECT_NEAR(plant.iron_C(), want(1), tolerance_K) << h;
    EXPECT_NEAR(plant.magnet_C(), want(2), tolerance_K) << h;
    EXPECT_GT(plant.winding_C() - 70.0, 5.0);  // it heated: the comparison is not of two constants
  }
}

TEST(ThermalPlant, SettlesWhereTheConductancesCarryTheLosses) {
  // Steady state: G·T = P + g_c·T_c; the whole loss leaves through the coolant's two paths.
  const ThermalPlantConfig c = warm_start();
  const ThermalLosses p{200.0, 80.0, 5.0};
  ThermalPlant plant(c, kBase);
  for (int k = 0; k < 40000; ++k) plant.step(p, kBase.omega_el_rad_s, 1.0);
  const Eigen::Vector3d want = exact(c, p, plant.gap_conductance_W_K(kBase.omega_el_rad_s), 1e9);
  EXPECT_NEAR(plant.winding_C(), want(0), 1e-9);
  EXPECT_NEAR(plant.magnet_C(), want(2), 1e-9);
  EXPECT_NEAR(plant.heat_to_coolant_W(), 285.0, 1e-9);
}

TEST(ThermalPlant, StoresExactlyWhatTheLossesBringAndTheCoolantTakes) {
  // Column sums of G are (0, G_sc, G_mc): the trapezoidal step's energy balance is exact,
  // ΔE = h·ΣP − h/2·(Q(T) + Q(T⁺)), whatever the step or the speed.
  ThermalPlant plant(warm_start(), kBase);
  const double e0 = plant.stored_heat_J();
  double budget_J = 0.0;
  for (int k = 0; k < 500; ++k) {
    const double omega = kBase.omega_el_rad_s * std::sin(0.01 * k);
    const ThermalLosses p{100.0 + k % 7, 30.0 * std::abs(std::sin(0.01 * k)), 1.0};
    const double before_W = plant.heat_to_coolant_W();
    plant.step(p, omega, 2.0);
    budget_J += 2.0 * (p.copper_W + p.iron_W + p.magnet_W) - (before_W + plant.heat_to_coolant_W());
  }
  EXPECT_NEAR(plant.stored_heat_J() - e0, budget_J, 1e-9 * std::abs(budget_J) + 1e-6);
}

TEST(ThermalPlant, LossFormsAtStatedPoints) {
  const ThermalPlantConfig c;  // P_h 40 W, P_e 25 W, β 1.8, P_pm 5 W at base
  const ThermalPlant plant(c, kBase);
  const core::Vec2 i(3.0, 4.0);  // 5 A
  const core::Vec2 psi_base(kBase.flux_Wb, 0.0);
  const ThermalLosses at_base = plant.losses(i, psi_base, kBase.omega_el_rad_s, 2.0);
  EXPECT_DOUBLE_EQ(at_base.copper_W, 1.5 * 2.0 * 25.0);
  EXPECT_NEAR(at_base.iron_W, 65.0, 1e-12);
  EXPECT_NEAR(at_base.magnet_W, 5.0 * std::pow(5.0 / kBase.current_A, 2), 1e-12);
  // Twice the frequency, reversed: hysteresis ∝ f, eddy ∝ f²; half the flux: (1/2)^β and (1/2)².
  EXPECT_NEAR(plant.losses(i, psi_base, -2.0 * kBase.omega_el_rad_s, 2.0).iron_W, 2.0 * 40.0 + 4.0 * 25.0, 1e-12);
  EXPECT_NEAR(plant.losses(i, 0.5 * psi_base, kBase.omega_el_rad_s, 2.0).iron_W, 40.0 * std::pow(0.5, 1.8) + 25.0 * 0.25,
              1e-12);
  EXPECT_DOUBLE_EQ(plant.losses(i, psi_base, 0.0, 2.0).iron_W, 0.0);
  EXPECT_DOUBLE_EQ(plant.gap_conductance_W_K(0.0), 1.5);
  EXPECT_DOUBLE_EQ(plant.gap_conductance_W_K(kBase.omega_el_rad_s), 1.5 * 3.0);
}

/// The paper's machine with the default thermal plant, averaged inverter, on the dynamometer; a DC link
/// (565 V) that needs no field weakening at base speed.
Scenario heated(double speed_rpm, double torque_Nm) {
  return parse_scenario(
      "duration_s: 2\ninverter: {model: averaged}\nlog: {temperatures: true}\n"
      "thermal_plant: {coolant_C: 30, winding_J_K: 800, iron_J_K: 2800, magnet_J_K: 1800, winding_iron_W_K: 8,\n"
      "  iron_coolant_W_K: 6, gap_W_K: 1.5, magnet_coolant_W_K: 0.5, hysteresis_W: 40, eddy_W: 25,\n"
      "  magnet_eddy_W: 5}\n"
      "initial: {u_dc_V: 565, speed_rpm: " +
          std::to_string(speed_rpm) + ", torque_Nm: " + std::to_string(torque_Nm) + "}\n",
      "heated.yaml", "");
}

TEST(ThermalPlantInTheDrive, TheWindingTakesTheCopperLossTheTruthShows) {
  // At standstill under load: no iron or magnet loss (f = 0); over 2 s the winding (τ ≈ C_w/G_ws = 100 s) holds
  // all but ≈ G_ws·t/(2·C_w) = 1 % of ∫(3/2)·R_s·|i|² dt / C_w, the copper loss computed here from the truth.
  DriveSimulator d(heated(0.0, 20.0));
  io::DriveLogRow row;
  TruthRow truth;
  double heat_J = 0.0;
  while (d.next(row, truth)) {
    heat_J += 1.5 * truth.parameters.r_s_Ohm * truth.i_dq_A.squaredNorm() * d.scenario().sample_period_s;
    EXPECT_DOUBLE_EQ(truth.parameters.r_s_Ohm, 2.25 * d.scenario().thermal.r_s.factor(truth.t_winding_C));
    EXPECT_DOUBLE_EQ(row.sample.t_coolant_C, 30.0);
  }
  const ThermalPlant& plant = *d.thermal_plant();
  const double rise_K = plant.winding_C() - 30.0;
  ASSERT_GT(heat_J, 50.0);  // ≈ 48 W at 20 N·m
  EXPECT_LT(rise_K, heat_J / 800.0);
  EXPECT_GT(rise_K, 0.985 * heat_J / 800.0);
  EXPECT_LT(plant.magnet_C() - 30.0, 1e-3 * rise_K);
  EXPECT_TRUE(d.layout().t_coolant);
}

TEST(ThermalPlantInTheDrive, TheIronTakesSteinmetzLossAtTheMagnetsFlux) {
  // At half base speed without torque the current is ≈ 0 (the back EMF, ω·ψm ≈ 180 V, needs no field
  // weakening) and |ψ| = ψm(30 °C): P_fe = 40·f·b^1.8 + 25·f²·b², f = 1/2, b = ψm/ψ_b; the iron's rise over 2 s
  // is P_fe·t/C_s (its conduction, G·ΔT ≈ 0.2 W, under 1 % of it).
  DriveSimulator d(heated(500.0, 0.0));
  io::DriveLogRow row;
  TruthRow truth;
  while (d.next(row, truth)) {
  }
  EXPECT_LT(truth.i_dq_A.norm(), 0.05);
  const double b = 1.14 * d.scenario().thermal.psi_m.factor(30.0) / kBase.flux_Wb;
  const double iron_W = 40.0 * 0.5 * std::pow(b, 1.8) + 25.0 * 0.25 * b * b;
  const ThermalPlant& plant = *d.thermal_plant();
  EXPECT_NEAR((plant.iron_C() - 30.0) / (iron_W * 2.0 / 2800.0), 1.0, 0.01);
  EXPECT_LT(plant.winding_C() - 30.0, 0.01 * (plant.iron_C() - 30.0));
}

TEST(ThermalPlantInTheDrive, WithoutItTheTemperaturesAreTheScenariosSignals) {
  Scenario s = heated(0.0, 0.0);
  s.thermal_plant.enabled = false;
  DriveSimulator d(std::move(s));
  EXPECT_EQ(d.thermal_plant(), nullptr);
  EXPECT_FALSE(d.layout().t_coolant);
}

}  // namespace
}  // namespace rpem::sim
