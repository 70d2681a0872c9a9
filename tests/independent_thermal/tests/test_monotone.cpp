// Monotone responses, each derived from the network's structure:
//  - From equilibrium at the coolant, with constant non-negative losses that depend on no temperature but
//    the winding's own (standstill with current), every node warms monotonically: the system is
//    cooperative (off-diagonal Jacobian ≥ 0) and dT/dt(0) ≥ 0, so dT/dt stays ≥ 0 (Kamke's theorem).
//  - More current or a warmer coolant: every steady-state temperature higher (G − a·e_w·e_wᵀ is an
//    M-matrix, its inverse non-negative, and the right-hand side grows).
//  - Without losses the stored heat Σ C_i·(T_i − T_c) only falls (its derivative is −(T − T_c)ᵀ·G·(T − T_c)
//    ≤ 0 with constant coolant), though one node may warm from another.
//  - The convective links grow with speed.
#include <gtest/gtest.h>

#include "fixtures.hpp"
#include "indep_thermal/convection.hpp"
#include "indep_thermal/network.hpp"

namespace indep_thermal {
namespace {

TEST(IndepThermalMonotone, HeatUpAtStandstillIsMonotoneInEveryNode) {
  const Machine m = test::paderborn_machine();
  const Parameters p = draw_parameters(m, 51);
  const Case c = test::exact_case(m, p, test::constant_profile(0.0, 0.0, 160.0, 4000.0), 4000.0, 2.0);
  const Result r = generate(c);
  for (std::size_t k = 1; k < r.rows.size(); ++k) {
    for (int i : {kTWinding, kTIron, kTRotor, kTSensorLag}) {
      EXPECT_GE(r.rows[k].truth.y(i), r.rows[k - 1].truth.y(i) - 1e-9) << "state " << i << " row " << k;
    }
  }
  EXPECT_GT(r.rows.back().truth.y(kTRotor) - p.coolant_start_C, 1.0);
}

Eigen::Vector3d final_temperatures(const Machine& m, const Parameters& p, double speed, double i_q) {
  const Case c = test::steady_case(m, p, speed, -0.3 * i_q, i_q, 20000.0, 0.01);
  return generate(c).rows.back().truth.y.head<3>();
}

TEST(IndepThermalMonotone, SteadyStateRisesWithCurrentAndCoolant) {
  const Machine m = test::paderborn_machine();
  Parameters p = draw_parameters(m, 52);
  const Eigen::Vector3d base = final_temperatures(m, p, 3000.0, 100.0);
  const Eigen::Vector3d more_current = final_temperatures(m, p, 3000.0, 110.0);
  p.coolant_start_C += 10.0;
  const Eigen::Vector3d warmer = final_temperatures(m, p, 3000.0, 100.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(more_current(i), base(i) + 0.1) << i;
    EXPECT_GT(warmer(i), base(i) + 9.0) << i;  // + 10 K, less the magnet's lower iron loss when warmer
  }
  // The winding gains more than 10 K: its resistance grows with it.
  EXPECT_GT(warmer(0), base(0) + 10.0);
}

TEST(IndepThermalMonotone, StoredHeatOnlyFallsWithoutLosses) {
  const Machine m = test::paper_machine();
  Parameters p = draw_parameters(m, 53);
  p.initial_rise_K = 60.0;
  const Case c = test::exact_case(m, p, test::constant_profile(0.0, 0.0, 0.0, 3000.0), 3000.0, 1.0);
  const Result r = generate(c);
  const Eigen::Vector3d cap = capacities(p);
  double last = 1e300;
  for (const Row& row : r.rows) {
    const double stored = cap.dot(row.truth.y.head<3>() - Eigen::Vector3d::Constant(p.coolant_start_C));
    EXPECT_LE(stored, last + 1e-9);
    last = stored;
  }
}

TEST(IndepThermalMonotone, ConvectiveLinksGrowWithSpeed) {
  const Parameters p = draw_parameters(test::paderborn_machine(), 54);
  Conductances last = conductances(p, 0.0);
  for (double w = 1.0; w < 2.5 * p.rated_speed_rad_s; w *= 1.1) {
    const Conductances g = conductances(p, w);
    EXPECT_GE(g.airgap, last.airgap);
    EXPECT_GT(g.winding_rotor, last.winding_rotor);
    EXPECT_GT(g.winding_coolant, last.winding_coolant);
    EXPECT_GT(g.rotor_coolant, last.rotor_coolant);
    EXPECT_EQ(g.winding_iron, last.winding_iron);
    EXPECT_EQ(g.iron_coolant, last.iron_coolant);
    last = g;
  }
  EXPECT_GT(conductances(p, p.rated_speed_rad_s).airgap, 1.05 * conductances(p, 0.0).airgap);
}

}  // namespace
}  // namespace indep_thermal
