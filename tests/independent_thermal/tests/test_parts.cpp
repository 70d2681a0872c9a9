// The parts against their defining formulas, computed here independently: materials, convection, the
// end-space star-delta, the network matrix, the loss laws, the steady-state voltages, the drive's current
// choice, profiles and the parameter draw.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <set>

#include "fixtures.hpp"
#include "indep_thermal/convection.hpp"
#include "indep_thermal/electrical.hpp"
#include "indep_thermal/errors.hpp"
#include "indep_thermal/losses.hpp"
#include "indep_thermal/materials.hpp"
#include "indep_thermal/network.hpp"
#include "indep_thermal/parameters.hpp"
#include "indep_thermal/pi.hpp"
#include "indep_thermal/profile.hpp"

namespace indep_thermal {
namespace {

TEST(IndepThermalMaterials, CopperIsLinearWithItsCoefficientAt20C) {
  Parameters p = nominal_parameters(test::paper_machine());
  // Reference 20 °C: R(T) = R20·(1 + α20·(T − 20)) exactly.
  for (double t : {-20.0, 20.0, 75.0, 155.0}) {
    EXPECT_NEAR(copper_resistance_Ohm(p, t), p.r_s_ref_Ohm * (1.0 + p.copper_alpha20_per_K * (t - 20.0)),
                1e-14 * p.r_s_ref_Ohm);
  }
  // Reference 115 °C: the configured value holds there, and R(20) = R_ref/(1 + α20·95).
  p.r_s_reference_C = 115.0;
  EXPECT_NEAR(copper_resistance_Ohm(p, 115.0), p.r_s_ref_Ohm, 1e-15);
  EXPECT_NEAR(copper_resistance_Ohm(p, 20.0), p.r_s_ref_Ohm / (1.0 + p.copper_alpha20_per_K * 95.0), 1e-14);
  // Annealed copper: zero resistance of the linear law at −234.5 °C (α20 = 3.93e-3: −234.45 °C).
  p.copper_alpha20_per_K = 3.93e-3;
  EXPECT_NEAR(copper_resistance_Ohm(p, -(1.0 / 3.93e-3 - 20.0)), 0.0, 1e-14);
}

TEST(IndepThermalMaterials, MagnetFluxFollowsRemanence) {
  Parameters p = nominal_parameters(test::paper_machine());
  p.psi_m_reference_C = 60.0;
  EXPECT_NEAR(magnet_flux_Wb(p, 60.0), p.psi_m_ref_Wb, 1e-15);
  // Br(T)/Br(20) = 1 + α·(T − 20): the ratio of two temperatures is the remanence ratio.
  const double a = p.magnet_alpha20_per_K;
  EXPECT_NEAR(magnet_flux_Wb(p, 140.0) / magnet_flux_Wb(p, 20.0), 1.0 + a * 120.0, 1e-14);
}

TEST(IndepThermalConvection, NusseltIsConductionThenVortexThenTurbulentAndContinuous) {
  const double pr = 0.7;
  const double f = std::pow(pr, 0.27);
  EXPECT_EQ(airgap_nusselt(0.0, pr), 2.0);
  EXPECT_EQ(airgap_nusselt(40.0, pr), 2.0);
  EXPECT_NEAR(airgap_nusselt(80.0, pr), 0.202 * std::pow(80.0, 0.63) * f, 1e-12);
  EXPECT_NEAR(airgap_nusselt(1000.0, pr), 0.386 * std::sqrt(1000.0) * f, 1e-12);
  // The two crossings, where the pieces meet.
  const double ta1 = std::pow(2.0 / (0.202 * f), 1.0 / 0.63);
  const double ta2 = std::pow(0.386 / 0.202, 1.0 / 0.13);
  for (double ta : {ta1, ta2}) {
    EXPECT_NEAR(airgap_nusselt(ta * (1 - 1e-9), pr), airgap_nusselt(ta * (1 + 1e-9), pr), 1e-7) << ta;
  }
  EXPECT_NEAR(ta1, 44.3, 0.1);
  EXPECT_NEAR(ta2, 146.0, 0.5);
  double last = 0.0;
  for (double ta = 0.0; ta < 1e5; ta = ta * 1.05 + 0.1) {
    const double nu = airgap_nusselt(ta, pr);
    EXPECT_GE(nu, last);
    last = nu;
  }
}

TEST(IndepThermalConvection, AirGapAtStandstillIsConductionAcrossTheGap) {
  const Parameters p = nominal_parameters(test::paderborn_machine());
  const double area = kPi * p.rotor_diameter_m * p.active_length_m;
  EXPECT_NEAR(airgap_conductance_W_K(p, 0.0), p.air_conductivity_W_mK / p.airgap_m * area, 1e-12);
  // Ta = Re·√(g/R), Re = Ω·R·g/ν.
  const double r = 0.5 * p.rotor_diameter_m;
  EXPECT_NEAR(taylor_number(p, 600.0), 600.0 * r * p.airgap_m / p.air_viscosity_m2_s * std::sqrt(p.airgap_m / r), 1e-9);
}

TEST(IndepThermalConvection, EndSpaceDeltaCarriesTheStarsHeat) {
  const Parameters p = nominal_parameters(test::paderborn_machine());
  const double omega = 0.7 * p.rated_speed_rad_s;
  const double v = omega * 0.5 * p.rotor_diameter_m;
  const double h = p.endspace_k1_W_m2K * (1.0 + p.endspace_k2 * std::pow(v, p.endspace_k3));
  const EndSpaceAreas a = endspace_areas(p);
  const double gw = h * a.winding_m2, gr = h * a.rotor_m2, gc = h * a.caps_m2;
  const double tw = 95.0, tr = 70.0, tc = 25.0;
  const double t_air = (gw * tw + gr * tr + gc * tc) / (gw + gr + gc);  // the massless air node's balance
  const EndSpaceConductances d = endspace_conductances(p, omega);
  EXPECT_NEAR(d.winding_rotor * (tw - tr) + d.winding_coolant * (tw - tc), gw * (tw - t_air), 1e-10);
  EXPECT_NEAR(d.winding_rotor * (tr - tw) + d.rotor_coolant * (tr - tc), gr * (tr - t_air), 1e-10);
  EXPECT_NEAR(d.winding_coolant * (tc - tw) + d.rotor_coolant * (tc - tr), gc * (tc - t_air), 1e-10);
}

TEST(IndepThermalNetwork, MatrixIsSymmetricPositiveDefiniteWithTheCoolantLinksAsRowSums) {
  const Parameters p = draw_parameters(test::paderborn_machine(), 5);
  for (double w : {0.0, 0.5 * p.rated_speed_rad_s, 1.3 * p.rated_speed_rad_s}) {
    const Conductances g = conductances(p, w);
    const Eigen::Matrix3d m = g.matrix();
    EXPECT_LT((m - m.transpose()).norm(), 1e-15);
    EXPECT_LT((m.rowwise().sum() - g.to_coolant()).norm(), 1e-9 * m.norm());
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues().minCoeff(), 0.0);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (i != j) {
          EXPECT_LE(m(i, j), 0.0);  // every link positive
        }
      }
    }
  }
}

TEST(IndepThermalLosses, RatedPointGivesTheRatedLosses) {
  Parameters p = nominal_parameters(test::paderborn_machine());
  p.l_d_H = 0.0;  // flux = ψm(T_r) whatever the current: B = 1 at T_r = T_ref
  p.l_q_H = 0.0;
  const double w = 2.0 * kPi * p.rated_frequency_Hz;
  const double i = p.rated_current_A;
  const Losses l = compute_losses(p, {w, 0.6 * i, -0.8 * i}, p.r_s_reference_C, p.psi_m_reference_C);
  EXPECT_NEAR(l.flux_rel, 1.0, 1e-14);
  EXPECT_NEAR(l.iron(), p.stator_iron_rated_W, 1e-9 * p.stator_iron_rated_W);
  EXPECT_NEAR(l.rotor_iron, p.rotor_iron_rated_W, 1e-9 * p.rotor_iron_rated_W);
  EXPECT_NEAR(l.magnet, p.magnet_rated_W, 1e-9 * p.magnet_rated_W);
  EXPECT_NEAR(l.mechanical, p.mechanical_rated_W, 1e-9 * p.mechanical_rated_W);
  EXPECT_NEAR(l.copper, 1.5 * p.r_s_ref_Ohm * (1.0 + p.ac_factor_at_rated) * i * i, 1e-9 * l.copper);
  EXPECT_NEAR(l.stator_hysteresis, p.stator_hysteresis_share * p.stator_iron_rated_W, 1e-9);
  EXPECT_NEAR(l.stator_excess, p.stator_excess_share * p.stator_iron_rated_W, 1e-9);
}

TEST(IndepThermalLosses, FrequencyAndFluxLaws) {
  const Parameters p = draw_parameters(test::paderborn_machine(), 9);
  const double w = 2.0 * kPi * p.rated_frequency_Hz * 0.4;
  const OperatingPoint op1{w, -30.0, 40.0};
  const OperatingPoint op2{2.0 * w, -30.0, 40.0};
  const Losses a = compute_losses(p, op1, 60.0, p.psi_m_reference_C);
  const Losses b = compute_losses(p, op2, 60.0, p.psi_m_reference_C);
  EXPECT_NEAR(b.stator_hysteresis / a.stator_hysteresis, 2.0, 1e-12);  // ∝ f
  EXPECT_NEAR(b.stator_eddy / a.stator_eddy, 4.0, 1e-12);              // ∝ f²
  EXPECT_NEAR(b.stator_excess / a.stator_excess, std::pow(2.0, 1.5), 1e-12);
  EXPECT_NEAR(b.magnet / a.magnet, 4.0, 1e-12);
  // Flux: B from the stator flux linkage; hysteresis ∝ B^β, eddy ∝ B².
  const double psi_d = magnet_flux_Wb(p, p.psi_m_reference_C) + p.l_d_H * -30.0;
  const double bb = std::hypot(psi_d, p.l_q_H * 40.0) / p.psi_m_ref_Wb;
  EXPECT_NEAR(a.flux_rel, bb, 1e-14);
  const double x = 0.4;
  const double eddy_share = 1.0 - p.stator_hysteresis_share - p.stator_excess_share;
  EXPECT_NEAR(a.stator_hysteresis,
              p.stator_iron_rated_W * p.stator_hysteresis_share * x * std::pow(bb, p.steinmetz_exponent), 1e-9);
  EXPECT_NEAR(a.stator_eddy, p.stator_iron_rated_W * eddy_share * x * x * bb * bb, 1e-9);
  // A hotter magnet carries less flux: less iron loss.
  EXPECT_LT(compute_losses(p, op1, 60.0, 120.0).iron(), a.iron());
  // Standstill: copper only.
  const Losses s = compute_losses(p, {0.0, 0.0, 50.0}, 60.0, 60.0);
  EXPECT_EQ(s.iron() + s.rotor(), 0.0);
  EXPECT_NEAR(s.copper, 1.5 * copper_resistance_Ohm(p, 60.0) * 2500.0, 1e-9);
}

TEST(IndepThermalElectrical, SteadyStateVoltageIsRiPlusJOmegaPsi) {
  const Parameters p = draw_parameters(test::paderborn_machine(), 2, {true});
  const OperatingPoint op{1800.0, -120.0, 70.0};
  const double t_w = 95.0, t_r = 80.0;
  const double f = 1800.0 / (2.0 * kPi);
  const double r = copper_resistance_Ohm(p, t_w) * (1.0 + p.ac_factor_at_rated * std::pow(f / p.rated_frequency_Hz, 2));
  const std::complex<double> i(op.i_d_A, op.i_q_A);
  const std::complex<double> psi(magnet_flux_Wb(p, t_r) + p.l_d_H * op.i_d_A, p.l_q_H * op.i_q_A);
  const std::complex<double> u = r * i + std::complex<double>(0.0, op.omega_el_rad_s) * psi;
  const DqVoltage v = steady_state_voltage(p, op, t_w, t_r);
  EXPECT_NEAR(v.u_d_V, u.real(), 1e-12 * std::abs(u));
  EXPECT_NEAR(v.u_q_V, u.imag(), 1e-12 * std::abs(u));
}

TEST(IndepThermalElectrical, MtpaMaximisesTorquePerAmpere) {
  const Machine m = test::paper_machine();
  for (double i_q : {1.0, 4.0, 9.0}) {
    const double i_d = mtpa_i_d_A(m.psi_m_Wb, m.l_d_H, m.l_q_H, i_q);
    const double amps = std::hypot(i_d, i_q);
    auto torque = [&](double beta) {  // current angle from the q axis towards −d
      const double d = -amps * std::sin(beta), q = amps * std::cos(beta);
      return m.psi_m_Wb * q + (m.l_d_H - m.l_q_H) * d * q;
    };
    double best = 0.0, best_beta = 0.0;
    for (int k = 0; k <= 200000; ++k) {
      const double beta = 0.5 * kPi * k / 200000.0;
      if (torque(beta) > best) best = torque(beta), best_beta = beta;
    }
    EXPECT_NEAR(std::atan2(-i_d, i_q), best_beta, 2e-5) << i_q;
  }
  EXPECT_EQ(mtpa_i_d_A(0.1, 1e-3, 1e-3, 50.0), 0.0);
}

TEST(IndepThermalElectrical, FieldWeakeningMeetsTheVoltageLimitAndTheCurrentLimitHolds) {
  const Machine m = test::paderborn_machine();
  const Parameters p = nominal_parameters(m);
  const double u_max = p.voltage_limit_rel * m.peak_voltage_V();
  const double i_max = p.current_limit_rel * m.peak_current_A();
  for (double speed : {500.0, 3000.0, 5500.0, 7000.0}) {
    for (double i_q : {0.0, 50.0, 150.0, 300.0, -150.0}) {
      const OperatingPoint op = drive_currents(m, p, {speed, i_q, 0.0, false}, 25.0);
      const double w = op.omega_el_rad_s;
      const double ud = m.r_s_Ohm * op.i_d_A - w * m.l_q_H * op.i_q_A;
      const double uq = m.r_s_Ohm * op.i_q_A + w * (m.l_d_H * op.i_d_A + m.psi_m_Wb);
      EXPECT_LE(std::hypot(ud, uq), u_max * (1 + 1e-9)) << speed << " " << i_q;
      EXPECT_LE(std::hypot(op.i_d_A, op.i_q_A), i_max * (1 + 1e-12));
      EXPECT_LE(op.i_d_A, mtpa_i_d_A(m.psi_m_Wb, m.l_d_H, m.l_q_H, op.i_q_A) + 1e-9);
      EXPECT_LE(std::abs(op.i_q_A), std::abs(i_q) + 1e-12);
    }
  }
  // Below base speed at moderate current: plain MTPA.
  const OperatingPoint low = drive_currents(m, p, {300.0, 100.0, 0.0, false}, 25.0);
  EXPECT_NEAR(low.i_d_A, mtpa_i_d_A(m.psi_m_Wb, m.l_d_H, m.l_q_H, 100.0), 1e-12);
  EXPECT_NEAR(low.i_q_A, 100.0, 1e-12);
}

TEST(IndepThermalElectrical, DeratingIsLinearInTheSensorTemperature) {
  const Machine m = test::paper_machine();
  const Parameters p = nominal_parameters(m);
  const Demand d{0.0, 4.0, -1.0, true};
  EXPECT_NEAR(drive_currents(m, p, d, p.derate_start_C).i_q_A, 4.0, 1e-12);
  EXPECT_NEAR(drive_currents(m, p, d, 0.5 * (p.derate_start_C + p.derate_end_C)).i_q_A, 2.0, 1e-12);
  EXPECT_EQ(drive_currents(m, p, d, p.derate_end_C + 5.0).i_q_A, 0.0);
  EXPECT_EQ(drive_currents(m, p, d, p.derate_end_C + 5.0).i_d_A, -1.0);
}

TEST(IndepThermalProfile, InterpolatesStepsAndTakesLeftLimits) {
  Profile p;
  p.gives_i_d = true;
  p.points = {{0, 0, 0, 0}, {10, 1000, 10, -5}, {10, 1000, 2, -1}, {20, 2000, 2, -1}};
  EXPECT_NEAR(p.at(5).speed_rpm, 500, 1e-12);
  EXPECT_NEAR(p.at(5).i_q_A, 5, 1e-12);
  EXPECT_EQ(p.at(10).i_q_A, 2.0);
  EXPECT_EQ(p.at(10, true).i_q_A, 10.0);
  EXPECT_EQ(p.at(10, true).i_d_A, -5.0);
  EXPECT_NEAR(p.at(15).speed_rpm, 1500, 1e-12);
  EXPECT_EQ(p.at(-1).speed_rpm, 0.0);
  EXPECT_EQ(p.at(99).speed_rpm, 2000.0);
  EXPECT_EQ(p.knots(), (std::vector<double>{0, 10, 20}));
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = std::string(RPEM_TEST_BINARY_DIR) + "/indep_thermal_" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(IndepThermalProfile, FileErrorsNameLineColumnAndWhy) {
  auto message = [](const std::string& path) {
    try {
      read_profile_csv(path);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string ok = write_temp("ok.csv", "# comment\nt_s,speed_rpm,i_q_A\n0,0,0\n\n5,100,2\n");
  const Profile p = read_profile_csv(ok);
  EXPECT_FALSE(p.gives_i_d);
  ASSERT_EQ(p.points.size(), 2u);
  EXPECT_EQ(p.points[1].i_q_A, 2.0);
  EXPECT_NE(message(write_temp("a.csv", "t_s,speed_rpm,iq\n")).find("a.csv:1:3: unknown column 'iq'"), std::string::npos);
  EXPECT_NE(
      message(write_temp("b.csv", "t_s,speed_rpm,i_q_A\n0,x,1\n")).find("b.csv:2:2: column speed_rpm: 'x' is not a number"),
      std::string::npos);
  EXPECT_NE(
      message(write_temp("c.csv", "t_s,speed_rpm,i_q_A\n5,0,1\n4,0,1\n")).find("c.csv:3:1: column t_s: time goes back"),
      std::string::npos);
  EXPECT_NE(message(write_temp("d.csv", "t_s,i_q_A\n")).find("d.csv:1: the header needs"), std::string::npos);
  EXPECT_NE(message(write_temp("e.csv", "t_s,speed_rpm,i_q_A\n0,0\n")).find("e.csv:2: 2 cells"), std::string::npos);
  EXPECT_NE(message(write_temp("f.csv", "t_s,speed_rpm,i_q_A\n")).find("no points"), std::string::npos);
  EXPECT_NE(message(write_temp("g.csv", "t_s,speed_rpm,i_q_A\n0,1e300,0\n")).find("beyond"), std::string::npos);
  EXPECT_NE(message("/nonexistent/profile.csv").find("cannot be read"), std::string::npos);
}

TEST(IndepThermalProfile, ShippedPaderbornLikeProfileReads) {
  const Profile p = read_profile_csv(std::string(RPEM_TEST_SOURCE_DIR) +
                                     "/tests/independent_thermal/profiles/paderborn_profile_a_like.csv");
  EXPECT_TRUE(p.gives_i_d);
  EXPECT_EQ(p.points.back().t_s, 7505.0);
  EXPECT_EQ(p.at(3000).speed_rpm, 5500.0);
}

TEST(IndepThermalProfile, DriveCycleIsSeededAndHasItsPhases) {
  const Machine m = test::paderborn_machine();
  const Profile a = drive_cycle_profile(m, 14400, 3);
  const Profile b = drive_cycle_profile(m, 14400, 3);
  const Profile c = drive_cycle_profile(m, 14400, 4);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t k = 0; k < a.points.size(); ++k) EXPECT_EQ(a.points[k].i_q_A, b.points[k].i_q_A);
  bool differ = a.points.size() != c.points.size();
  for (std::size_t k = 0; !differ && k < a.points.size(); ++k) differ = a.points[k].i_q_A != c.points[k].i_q_A;
  EXPECT_TRUE(differ);
  EXPECT_EQ(a.points.back().t_s, 14400.0);
  double standstill_with_current = 0, high_speed_low_current = 0, idle = 0;
  for (double t = 0; t < 14400; t += 1.0) {
    const Demand d = a.at(t);
    const double i = std::abs(d.i_q_A) / m.peak_current_A();
    const double n = std::abs(d.speed_rpm) / m.speed_rpm;
    standstill_with_current += (n == 0.0 && i >= 0.3);
    high_speed_low_current += (n >= 0.8 && i <= 0.4);
    idle += (n == 0.0 && i == 0.0);
  }
  EXPECT_GT(standstill_with_current, 300);
  EXPECT_GT(high_speed_low_current, 300);
  EXPECT_GT(idle, 100);
}

TEST(IndepThermalParameters, DrawStaysWithinTheCatalogueAndIsSeeded) {
  const Machine m = test::paderborn_machine();
  const Parameters nominal = nominal_parameters(m);
  const Parameters a = draw_parameters(m, 17);
  const Parameters e = draw_parameters(m, 17, {true});
  const Parameters b = draw_parameters(m, 18);
  for (const CatalogueEntry& c : catalogue()) {
    const double x0 = nominal.*c.field, x = a.*c.field, xe = e.*c.field;
    switch (c.draw) {
      case Draw::fixed:
        EXPECT_EQ(x, x0) << c.key;
        break;
      case Draw::factor:
        EXPECT_GE(x / x0, c.lo * (1 - 1e-12)) << c.key;
        EXPECT_LE(x / x0, c.hi * (1 + 1e-12)) << c.key;
        EXPECT_NE(x, b.*c.field) << c.key;
        break;
      case Draw::uniform:
        EXPECT_GE(x, c.lo) << c.key;
        EXPECT_LE(x, c.hi) << c.key;
        break;
      case Draw::electrical_factor:
        EXPECT_EQ(x, x0) << c.key;
        EXPECT_GE(xe / x0, c.lo * (1 - 1e-12)) << c.key;
        EXPECT_LE(xe / x0, c.hi * (1 + 1e-12)) << c.key;
        EXPECT_NE(xe, x0) << c.key;
        break;
    }
    if (c.draw != Draw::electrical_factor) {
      EXPECT_EQ(x, xe) << c.key;  // the electrical draw shifts nothing else
    }
    EXPECT_EQ(x, draw_parameters(m, 17).*c.field) << c.key;
  }
}

TEST(IndepThermalParameters, SetGetAndValidateNameTheKey) {
  Parameters p = nominal_parameters(test::paper_machine());
  set_parameter(p, "capacity.rotor_J_K", 1234.0);
  EXPECT_EQ(p.c_rotor_J_K, 1234.0);
  EXPECT_EQ(get_parameter(p, "capacity.rotor_J_K"), 1234.0);
  try {
    set_parameter(p, "capacity.rotor", 1.0);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown parameter 'capacity.rotor' (known: electrical.r_s_reference_C"),
              std::string::npos);
  }
  set_parameter(p, "conductance.shaft_W_K", -1.0);
  try {
    validate(p);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "parameter conductance.shaft_W_K: must be > 0");
  }
  std::set<std::string> keys;
  for (const CatalogueEntry& c : catalogue()) EXPECT_TRUE(keys.insert(c.key).second) << c.key;
}

TEST(IndepThermalMachine, ConfigurationErrorsNameFileLineAndKey) {
  const Machine m = test::paper_machine();
  EXPECT_EQ(m.pole_pairs, 3);
  EXPECT_NEAR(m.rated_torque_Nm(), 32.6, 1e-12);
  EXPECT_NEAR(test::paderborn_machine().rated_torque_Nm(), 0.85 * std::sqrt(3.0) * 170 * 160 / (2 * kPi * 6000 / 60.0),
              1e-9);
  const std::string bad = write_temp("bad.yaml",
                                     "machine:\n  rated:\n    voltage_ll_rms_V: 400\n    current_rms_A: 5\n"
                                     "    speed_rpm: 1000\n    pole_pairs: 2.5\n");
  try {
    read_machine(bad);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:6: machine.rated.pole_pairs: not an integer"), std::string::npos);
  }
}

}  // namespace
}  // namespace indep_thermal
