// GIVEN tab_machineData's name plate WHEN the per-unit base is built THEN it matches the hand-worked base.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/per_unit.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

TEST(PerUnit, PaperBaseMatchesHandComputation) {
  const PerUnitBase b = test::paper_base();
  EXPECT_NEAR(b.voltage_V, std::sqrt(2.0) * 400.0 / std::sqrt(3.0), 1e-12);  // 326.60 V
  EXPECT_NEAR(b.current_A, std::sqrt(2.0) * 4.93, 1e-12);                   // 6.972 A
  EXPECT_NEAR(b.omega_el_rad_s, 100.0 * kPi, 1e-12);                        // 3 pole pairs at 1000 rpm: 50 Hz
  EXPECT_NEAR(b.flux_Wb, b.voltage_V / (100.0 * kPi), 1e-12);
  // tab_machineData's rated torque, 32.6 Nm, is this base's torque T_b = 1.5·p·ψ_b·I_b (to print precision).
  EXPECT_NEAR(b.torque_Nm, 32.6, 0.05);
}

TEST(PerUnit, PaperFluxInconsistencyIsTheVoltageBase) {
  const PerUnitBase b = test::paper_base();
  // 1.14 Wb in our (peak phase) base:
  EXPECT_NEAR(b.flux_pu(1.14), 1.0966, 1e-4);
  // Section VI's 0.895 pu is 1.14 Wb only against ψ_b = U_n/ω_n with U_n the line-to-line rms voltage.
  EXPECT_NEAR(1.14 / (400.0 / (100.0 * kPi)), 0.895, 5e-4);
}

TEST(PerUnit, ConversionsRoundTrip) {
  const PerUnitBase b = test::paper_base();
  for (double v : {-3.0, 0.0, 0.125, 7.5}) {
    EXPECT_DOUBLE_EQ(b.voltage_V_of(b.voltage_pu(v)), v);
    EXPECT_DOUBLE_EQ(b.current_A_of(b.current_pu(v)), v);
    EXPECT_DOUBLE_EQ(b.flux_Wb_of(b.flux_pu(v)), v);
    EXPECT_DOUBLE_EQ(b.resistance_Ohm_of(b.resistance_pu(v)), v);
    EXPECT_DOUBLE_EQ(b.inductance_H_of(b.inductance_pu(v)), v);
    EXPECT_DOUBLE_EQ(b.torque_Nm_of(b.torque_pu(v)), v);
    EXPECT_NEAR(b.omega_el_rad_s_of(b.speed_pu(v)), v, 1e-15);
    EXPECT_NEAR(b.mech_speed_rpm_of(b.mech_speed_rpm_to_pu(v)), v, 1e-12);
  }
  EXPECT_NEAR(b.mech_speed_rpm_to_pu(100.0), 0.1, 1e-15);  // Section V's |100| rpm
}

TEST(PerUnit, PaperMachineInPu) {
  const MachinePu m = test::paper_machine_pu();
  const PerUnitBase b = test::paper_base();
  EXPECT_NEAR(m.r_s_pu, 2.25 / (b.voltage_V / b.current_A), 1e-15);
  EXPECT_NEAR(m.x_d_pu, 0.6391, 1e-4);
  EXPECT_NEAR(m.x_q_pu, 1.3815, 1e-4);
  EXPECT_NEAR(m.r_s_pu, 0.04803, 1e-5);
}

}  // namespace
}  // namespace rpem::core
