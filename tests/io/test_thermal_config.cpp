// The `thermal` section (io/thermal_config.hpp, docs/thermal.md): what the writer writes reads back to the
// same values; every bad section is refused with file:line:column, the key and the reason; the defaults
// come from the machine and the materials' table (core/thermal.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <regex>
#include <string>
#include <vector>

#include "rpem/io/thermal_config.hpp"
#include "support/temp_file.hpp"

namespace rpem::io {
namespace {

const char* kThreeNodes = R"(thermal:
  nodes:
    - {name: winding, capacitance_J_per_K: 4200, to_coolant_W_per_K: 3, process_noise_K2_per_s: 0.001, disturbance_W2_per_s: 2}
    - {name: stator_iron, capacitance_J_per_K: 11000, to_coolant_W_per_K: 95}
    - {name: magnet, capacitance_J_per_K: 6500, to_coolant_W_per_K: 2.5, to_coolant_at_base_speed_W_per_K: 4}
  conductances:
    - {from: winding, to: stator_iron, W_per_K: 44}
    - {from: magnet, to: stator_iron, W_per_K: 13, at_base_speed_W_per_K: 6}
  losses:
    - {form: iron_hysteresis, node: stator_iron, at_base_W: 210, rel_sigma: 0.3}
    - {form: magnet_eddy, node: magnet, at_base_W: 35}
  loss_base: {omega_el_rad_s: 2000, psi_Wb: 0.1, current_A: 150}
  copper: {r_s_ref_Ohm: 0.07, reference_C: 120, coeff_per_K: 0.0028, reference_sigma_K: 2, coeff_rel_sigma: 0.05, loss_rel_sigma: 0.08}
  magnet_law: {psi_m_ref_Wb: 0.117, reference_C: 20, coeff_per_K: -0.00105}
  coolant_C: 35
  coolant_drift_K2_per_s: 0.0025
  winding_sensor: {sigma_K: 1.5, time_constant_s: 12, node: reading}
  filter: {period_s: 0.5, initial_sigma_K: 5, gate_sigma: 4, gate_reset_after: 2, residual_time_constant_s: 8, settle_time_constants: 4}
)";

/// The paper's machine with bounds that hold the fixtures' laws (a 0.117 Wb, 70 mΩ machine's): a law no bounded
/// estimate reads as a possible temperature is another machine's, and refused (AnotherMachinesLawIsRefused).
MachineConfig machine() {
  MachineConfig m = builtin_paper_config();
  m.estimator.psi_m_min_Wb = 0.05;
  m.estimator.r_s_min_Ohm = 0.03;
  return m;
}

ThermalConfig load_text(const std::string& text) {
  test::TempFile f("thermal.yaml", text);
  return load_thermal_config(f.path(), machine());
}

/// The reader's error on `text` for machine `m`, "" if it reads.
std::string load_error(const std::string& text, const MachineConfig& m = machine()) {
  test::TempFile f("thermal.yaml", text);
  try {
    (void)load_thermal_config(f.path(), m);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string error_of(const std::string& pattern, const std::string& replacement) {
  const std::string text = std::regex_replace(std::string(kThreeNodes), std::regex(pattern), replacement,
                                              std::regex_constants::format_first_only);
  EXPECT_NE(text, kThreeNodes) << "pattern did not match: " << pattern;
  return load_error(text);
}

TEST(ThermalConfig, ReadsEveryKeyAndTheWriterReadsBack) {
  const ThermalConfig c = load_text(kThreeNodes);
  const core::ThermalNetwork& n = c.fusion.filter.network;
  ASSERT_EQ(n.nodes, 3);
  EXPECT_EQ(n.winding, 0);
  EXPECT_EQ(n.magnet, 2);
  EXPECT_EQ(c.node_names[1], "stator_iron");
  EXPECT_DOUBLE_EQ(n.capacitance_J_per_K[1], 11000.0);
  EXPECT_DOUBLE_EQ(n.to_coolant_at_base_speed_W_per_K[2], 4.0);
  EXPECT_DOUBLE_EQ(n.to_coolant_at_base_speed_W_per_K[1], 0.0);  // absent: no speed part
  EXPECT_DOUBLE_EQ(n.between_W_per_K(2, 1), 13.0);
  EXPECT_DOUBLE_EQ(n.between_at_base_speed_W_per_K(1, 2), 6.0);  // the air gap's speed part, symmetric
  EXPECT_DOUBLE_EQ(n.between_at_base_speed_W_per_K(2, 1), 6.0);
  EXPECT_DOUBLE_EQ(n.between_at_base_speed_W_per_K(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(n.between_W_per_K(0, 2), 0.0);
  EXPECT_DOUBLE_EQ(n.loss_at_base_W(static_cast<int>(core::LossForm::kIronHysteresis), 1), 210.0);
  EXPECT_DOUBLE_EQ(c.fusion.filter.loss_rel_sigma(static_cast<int>(core::LossForm::kIronHysteresis), 1), 0.3);
  EXPECT_DOUBLE_EQ(c.fusion.filter.loss_rel_sigma(static_cast<int>(core::LossForm::kMagnetEddy), 2), 0.5);  // default
  EXPECT_DOUBLE_EQ(n.copper.reference_C, 120.0);
  EXPECT_DOUBLE_EQ(c.fusion.filter.copper_rel_sigma, 0.08);
  EXPECT_DOUBLE_EQ(c.fusion.filter.calibration_sigma[static_cast<int>(core::Calibration::kCopperOffset)], 2.0);
  EXPECT_DOUBLE_EQ(c.fusion.magnet_law.coeff_per_K, -0.00105);
  EXPECT_DOUBLE_EQ(c.fusion.winding_sensor_sigma_K, 1.5);
  EXPECT_DOUBLE_EQ(c.fusion.winding_sensor_time_constant_s, 12.0);
  EXPECT_TRUE(c.fusion.winding_node_is_reading);
  EXPECT_DOUBLE_EQ(c.fusion.observer.period_s, 0.5);
  EXPECT_EQ(c.fusion.filter.gate_reset_after, 2);
  EXPECT_DOUBLE_EQ(c.fusion.filter.disturbance_W2_per_s[0], 2.0);
  EXPECT_DOUBLE_EQ(c.fusion.filter.coolant_drift_K2_per_s, 0.0025);

  const ThermalConfig back = load_text(thermal_config_yaml(c));
  const core::ThermalNetwork& m = back.fusion.filter.network;
  EXPECT_EQ(m.nodes, n.nodes);
  EXPECT_EQ(back.node_names, c.node_names);
  EXPECT_EQ(m.capacitance_J_per_K, n.capacitance_J_per_K);
  EXPECT_EQ(m.to_coolant_W_per_K, n.to_coolant_W_per_K);
  EXPECT_EQ(m.to_coolant_at_base_speed_W_per_K, n.to_coolant_at_base_speed_W_per_K);
  EXPECT_EQ(m.between_W_per_K, n.between_W_per_K);
  EXPECT_EQ(m.between_at_base_speed_W_per_K, n.between_at_base_speed_W_per_K);
  EXPECT_EQ(m.loss_at_base_W, n.loss_at_base_W);
  EXPECT_EQ(back.fusion.filter.loss_rel_sigma, c.fusion.filter.loss_rel_sigma);
  EXPECT_EQ(back.fusion.filter.calibration_sigma, c.fusion.filter.calibration_sigma);
  EXPECT_EQ(back.fusion.filter.process_noise_K2_per_s, c.fusion.filter.process_noise_K2_per_s);
  EXPECT_DOUBLE_EQ(m.copper.value_ref, n.copper.value_ref);
  EXPECT_DOUBLE_EQ(back.fusion.magnet_law.value_ref, c.fusion.magnet_law.value_ref);
  EXPECT_DOUBLE_EQ(back.fusion.coolant_C, 35.0);
  EXPECT_DOUBLE_EQ(back.fusion.filter.coolant_drift_K2_per_s, 0.0025);
  EXPECT_DOUBLE_EQ(back.fusion.winding_sensor_time_constant_s, 12.0);
  EXPECT_TRUE(back.fusion.winding_node_is_reading);
  EXPECT_DOUBLE_EQ(m.base.current_A, 150.0);
}

TEST(ThermalConfig, DefaultsComeFromTheMachineAndTheMaterials) {
  const MachineConfig mc = machine();
  const ThermalConfig c = default_thermal_config(mc);
  EXPECT_DOUBLE_EQ(c.fusion.magnet_law.value_ref, mc.machine.psi_m_Wb);
  EXPECT_DOUBLE_EQ(c.fusion.magnet_law.coeff_per_K, core::kNdFeB.typical_per_K);
  EXPECT_DOUBLE_EQ(c.fusion.filter.network.copper.value_ref, mc.machine.r_s_Ohm);
  // The built-in machine has no rs_drift: r_s_Ohm is assumed at copper's 20 °C, and the fit must say so.
  EXPECT_DOUBLE_EQ(c.fusion.filter.network.copper.reference_C, 20.0);
  EXPECT_FALSE(c.copper_reference_stated);
  EXPECT_FALSE(c.magnet_law_stated);  // nor psim_drift: ψm assumed at NdFeB's 20 °C
  // σ of α (eq. 14.11a): NdFeB's typical −0.12 %/K is 0.04 %/K from its range's farther end (−0.08), half of
  // which is 16.7 % of it, more than the uniform spread's 0.05/(√12·0.12) = 12.0 %. Copper: the uniform's 8.7 %.
  EXPECT_NEAR(c.fusion.filter.calibration_sigma[static_cast<int>(core::Calibration::kMagnetCoefficient)],
              0.5 * 0.0004 / 0.0012, 1e-12);
  EXPECT_NEAR(c.fusion.filter.calibration_sigma[static_cast<int>(core::Calibration::kCopperCoefficient)],
              0.3 / std::sqrt(12.0), 1e-12);
  const core::PerUnitBase base = core::PerUnitBase::from_rated(mc.machine.rated);
  EXPECT_DOUBLE_EQ(c.fusion.filter.network.base.omega_el_rad_s, base.omega_el_rad_s);
  EXPECT_DOUBLE_EQ(c.fusion.filter.network.base.current_A, base.current_A);
}

TEST(ThermalConfig, BadSectionsNameFileLineKeyAndReason) {
  EXPECT_NE(error_of("name: magnet", "name: rotor").find("a node named 'magnet' is required"), std::string::npos);
  EXPECT_NE(
      error_of("name: stator_iron", "name: winding").find(":4:14: thermal.nodes[1].name: node 'winding' appears twice"),
      std::string::npos)
      << error_of("name: stator_iron", "name: winding");
  EXPECT_NE(error_of("form: magnet_eddy", "form: magnet_hysteresis")
                .find("unknown loss form 'magnet_hysteresis' (one of iron_hysteresis, iron_eddy, magnet_eddy)"),
            std::string::npos);
  EXPECT_NE(error_of("to: stator_iron, W_per_K: 44", "to: rotor, W_per_K: 44").find("no node named 'rotor'"),
            std::string::npos);
  EXPECT_NE(error_of("from: magnet, to: stator_iron", "from: winding, to: stator_iron").find("is given twice"),
            std::string::npos);
  // The magnet without a conductance of its own to the coolant still reaches it through the stator iron.
  EXPECT_EQ(
      error_of("capacitance_J_per_K: 6500, to_coolant_W_per_K: 2.5", "capacitance_J_per_K: 6500, to_coolant_W_per_K: 0"),
      "");
  EXPECT_NE(error_of("capacitance_J_per_K: 6500, to_coolant_W_per_K: 2.5", "capacitance_J_per_K: -1")
                .find("thermal.nodes[2].capacitance_J_per_K: -1 is outside"),
            std::string::npos);
  EXPECT_NE(error_of("coolant_C: 35", "coolant_C: 35\n  coolnat: 3").find("thermal.coolnat"), std::string::npos);
  EXPECT_NE(error_of("coolant_drift_K2_per_s: 0.0025", "coolant_drift_K2_per_s: -1")
                .find("thermal.coolant_drift_K2_per_s: -1 is outside"),
            std::string::npos);
  // A required key misspelt: the error points at what was given, not only at the key that is missing.
  EXPECT_NE(error_of("capacitance_J_per_K: 6500", "capacitence_J_per_K: 6500")
                .find(":5:22: thermal.nodes[2].capacitance_J_per_K: required key is missing; `capacitence_J_per_K` is "
                      "given: misspelt?"),
            std::string::npos)
      << error_of("capacitance_J_per_K: 6500", "capacitence_J_per_K: 6500");
  // eq. 14.1b's speed part: never negative, named with its place.
  EXPECT_NE(error_of("to_coolant_at_base_speed_W_per_K: 4", "to_coolant_at_base_speed_W_per_K: -4")
                .find("thermal.nodes[2].to_coolant_at_base_speed_W_per_K: -4 is outside"),
            std::string::npos);
  EXPECT_NE(error_of("at_base_speed_W_per_K: 6", "at_base_speed_W_per_K: -6")
                .find("thermal.conductances[1].at_base_speed_W_per_K: -6 is outside"),
            std::string::npos);
  // The sensor's lag: 0 (none) by default, never negative, a misspelt key named.
  EXPECT_DOUBLE_EQ(load_text(std::regex_replace(std::string(kThreeNodes), std::regex(", time_constant_s: 12"), ""))
                       .fusion.winding_sensor_time_constant_s,
                   0.0);
  EXPECT_NE(
      error_of("time_constant_s: 12", "time_constant_s: -3").find("thermal.winding_sensor.time_constant_s: -3 is outside"),
      std::string::npos)
      << error_of("time_constant_s: 12", "time_constant_s: -3");
  EXPECT_NE(error_of("time_constant_s: 12", "time_constnat_s: 12").find("thermal.winding_sensor.time_constnat_s"),
            std::string::npos)
      << error_of("time_constant_s: 12", "time_constnat_s: 12");
  // What the winding node stands for (eq. 14.24): the winding unless `node: reading` says the sensor's reading.
  EXPECT_FALSE(load_text(std::regex_replace(std::string(kThreeNodes), std::regex(", node: reading"), ""))
                   .fusion.winding_node_is_reading);
  EXPECT_NE(error_of("node: reading", "node: sensor").find("thermal.winding_sensor.node"), std::string::npos)
      << error_of("node: reading", "node: sensor");
  EXPECT_NE(error_of("coeff_per_K: -0.00105", "coeff_per_K: 0.00105").find("thermal.magnet_law.coeff_per_K"),
            std::string::npos);
  // A magnet cut off from everything: no steady state.
  const std::string cut = std::regex_replace(
      std::regex_replace(std::string(kThreeNodes),
                         std::regex("    - \\{from: magnet, to: stator_iron, W_per_K: 13, at_base_speed_W_per_K: 6\\}\n"),
                         ""),
      std::regex("to_coolant_W_per_K: 2.5"), "to_coolant_W_per_K: 0");
  try {
    (void)load_text(cut);
    ADD_FAILURE() << "accepted a node without a path to the coolant";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("node 'magnet' has no path of conductances to the coolant"), std::string::npos)
        << e.what();
  }
}

TEST(ThermalConfig, ANetworkWhoseWindingRunsAwayAtTheRatingIsRefused) {
  // eq. 14.27 at the machine's rated point (the built-in paper machine: 4.93 A rms, so |i|² = 48.6 A²). The
  // winding's conductance to the coolant, directly (3 W/K) and through the stator iron (44 W/K in series with
  // the iron's 95 W/K and the magnet's path), is about 33 W/K; copper's rise K = 1.5·R_ref·α·|i|² is 0.014 W/K at
  // the section's 0.07 Ω and 143 W/K at 700 Ω: refused, naming the key, the rated point and both figures.
  const std::string error = error_of("r_s_ref_Ohm: 0.07,", "r_s_ref_Ohm: 700,");
  EXPECT_NE(error.find(":3:5: thermal.nodes: the network has no steady state at the machine's rated point (6.972 A peak"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("the copper loss grows by 142.9 W/K"), std::string::npos) << error;
  // The figure it is held against: the winding's conductance to the coolant, reduced here by hand as series and
  // parallel paths (the core inverts the conductance matrix): 3 W/K directly, and 44 W/K in series with the iron's
  // 95 W/K to the coolant in parallel with the magnet's path (13 + 6·s W/K in series with 2.5 + 4·s W/K),
  // s = √(ω_rated/ω_b) with the section's ω_b = 2000 rad/s (eq. 14.1b).
  const double s = std::sqrt(core::PerUnitBase::from_rated(machine().machine.rated).omega_el_rad_s / 2000.0);
  const auto series = [](double a, double b) { return 1.0 / (1.0 / a + 1.0 / b); };
  const double conducted = 3.0 + series(44.0, 95.0 + series(13.0 + 6.0 * s, 2.5 + 4.0 * s));
  char figure[64];
  std::snprintf(figure, sizeof figure, "at least the %.4g W/K the winding conducts to the coolant", conducted);
  EXPECT_NE(error.find(figure), std::string::npos) << figure << "\n" << error;
  EXPECT_NE(error.find("eq. 14.27"), std::string::npos) << error;
  // The same network at 10 Ω settles (K = 2.04 W/K): the check is the steady state's, not a bound on R_ref.
  EXPECT_EQ(error_of("r_s_ref_Ohm: 0.07,", "r_s_ref_Ohm: 10,"), "");
}

TEST(ThermalConfig, DisturbanceTimeConstantPerNodeAbsentIsTheWalk) {
  // eq. 14.19: a node's τ_d; absent, +∞ (the random walk, eq. 14.9), and the writer then leaves it out.
  const std::string text = std::regex_replace(std::string(kThreeNodes), std::regex("to_coolant_W_per_K: 95"),
                                              "to_coolant_W_per_K: 95, disturbance_time_constant_s: 1800");
  const ThermalConfig c = load_text(text);
  const core::ThermalVec& tau = c.fusion.filter.disturbance_time_constant_s;
  EXPECT_DOUBLE_EQ(tau[1], 1800.0);
  EXPECT_TRUE(std::isinf(tau[0]) && tau[0] > 0.0);
  EXPECT_TRUE(std::isinf(tau[2]) && tau[2] > 0.0);
  const std::string written = thermal_config_yaml(c);
  EXPECT_EQ(written.find("disturbance_time_constant_s"), written.rfind("disturbance_time_constant_s"));  // once
  const ThermalConfig back = load_text(written);
  EXPECT_EQ(back.fusion.filter.disturbance_time_constant_s, tau);
  // Strict as the other keys: a number, inside [1 s, 10⁹ s], with file:line:column.
  for (const char* bad : {"0.5", "-3", "2e9", "long", ".inf"}) {
    const std::string e =
        error_of("to_coolant_W_per_K: 95", std::string("to_coolant_W_per_K: 95, disturbance_time_constant_s: ") + bad);
    EXPECT_NE(e.find(":4:"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("thermal.nodes[1].disturbance_time_constant_s"), std::string::npos) << bad << ": " << e;
  }
}

// A thermal.yaml fitted with another machine's configuration (rpem estimate --config A --thermal B's): its laws read
// every estimate the bounds allow as an impossible temperature, and it is refused with the law's place.
TEST(ThermalConfig, AnotherMachinesLawIsRefused) {
  const MachineConfig paper = builtin_paper_config();  // ψm in [0.57, 1.71] Wb, R_s in [1, 4.5] Ω
  const auto error_with = [&](const std::string& text) { return load_error(text, paper); };
  // 20 + (0.57/0.117 − 1)/(−0.00105) = −3 667 °C and 20 + (1.71/0.117 − 1)/(−0.00105) = −12 947 °C.
  const std::string magnet = error_with(kThreeNodes);
  EXPECT_NE(magnet.find(":14:15: thermal.magnet_law: magnet_law reads the estimator's whole range "
                        "estimator.bounds.psi_m_Wb [0.57, 1.71] as -1.295e+04 to -3667 °C, outside -273.1 to 400 °C"),
            std::string::npos)
      << magnet;
  // The magnet law the machine's, the copper law still the 70 mΩ one: 120 + (1/0.07 − 1)/0.0028 = 4 865 °C.
  const std::string with_magnet =
      std::regex_replace(std::string(kThreeNodes), std::regex("psi_m_ref_Wb: 0.117"), "psi_m_ref_Wb: 1.2");
  const std::string copper = error_with(with_magnet);
  EXPECT_NE(copper.find(":13:11: thermal.copper: copper law reads the estimator's whole range "
                        "estimator.bounds.r_s_Ohm [1, 4.5] as 4865 to"),
            std::string::npos)
      << copper;
  // A law that reads one end of the bounds as a possible temperature is kept: ψm 0.5 Wb at 20 °C reads 0.57 Wb as
  // 20 + (1.14 − 1)/(−0.00105) = −113 °C; likewise R_s 0.9 Ω at 120 °C reads 1 Ω as
  // 120 + (1/0.9 − 1)/0.0028 = 160 °C.
  const std::string near =
      std::regex_replace(std::regex_replace(with_magnet, std::regex("psi_m_ref_Wb: 1.2"), "psi_m_ref_Wb: 0.5"),
                         std::regex("r_s_ref_Ohm: 0.07"), "r_s_ref_Ohm: 0.9");
  EXPECT_EQ(error_with(near), "");
}

// A larger machine's magnet law read with a smaller one's bounds: every value reads near T_ref + 1/|α| (−0.00105/K:
// 972 °C), below the plausible 1 000 °C, so the absolute limits kept it (a walk's VESC 6374 configuration with a law
// fitted on Paderborn's bench read ψ̂m as 815 °C). Its coefficient is NdFeB's, whose Curie temperature (at most 400 °C)
// no reading of a magnet can exceed: refused. ψ_ref 10 Wb with the paper machine's [0.57, 1.71] Wb:
// 20 + (1.71/10 − 1)/(−0.00105) = 809.5 °C to 20 + (0.57/10 − 1)/(−0.00105) = 918.1 °C. The same law with SmCo's
// coefficient (−0.0004/K) reads the bounds' top as 20 + (0.171 − 1)/(−0.0004) = 2 092.5 °C, beyond SmCo's Curie
// temperature (at most 920 °C): refused; at ψ_ref 2 Wb it reads 1.71 Wb as 20 + (0.855 − 1)/(−0.0004) = 382.5 °C, a SmCo
// magnet's possible temperature, and is kept.
TEST(ThermalConfig, AMagnetLawReadingEveryValueAboveItsMaterialsCurieTemperatureIsRefused) {
  const MachineConfig paper = builtin_paper_config();
  const auto law = [](const char* psi_ref, const char* coeff) {
    return std::regex_replace(
        std::string(kThreeNodes),
        std::regex("magnet_law: \\{psi_m_ref_Wb: 0.117, reference_C: 20, coeff_per_K: -0.00105\\}"),
        std::string("magnet_law: {psi_m_ref_Wb: ") + psi_ref + ", reference_C: 20, coeff_per_K: " + coeff + "}");
  };
  const auto with_copper = [](std::string text) {  // the copper law the paper machine's, so that only the magnet's is judged
    return std::regex_replace(text, std::regex("r_s_ref_Ohm: 0.07"), "r_s_ref_Ohm: 2.4");
  };
  const std::string ndfeb = with_copper(law("10", "-0.00105"));
  ASSERT_NE(ndfeb, with_copper(std::string(kThreeNodes)));
  const std::string e = load_error(ndfeb, paper);
  EXPECT_NE(e.find("thermal.magnet_law: magnet_law reads the estimator's whole range estimator.bounds.psi_m_Wb [0.57, "
                   "1.71] as 809.5 to 918.1 °C, outside -273.1 to 400 °C (absolute zero to the highest Curie temperature "
                   "of the magnet material its coefficient is)"),
            std::string::npos)
      << e;
  const std::string smco = load_error(with_copper(law("10", "-0.0004")), paper);
  EXPECT_NE(smco.find("[0.57, 1.71] as 2092 to 2378 °C, outside -273.1 to 920 °C"), std::string::npos) << smco;
  EXPECT_EQ(load_error(with_copper(law("2", "-0.0004")), paper), "");
  EXPECT_EQ(load_error(with_copper(law("1.2", "-0.00105")), paper), "");  // the machine's own: kept
}

TEST(ThermalConfig, AnAssumedLawIsANote) {
  // Without magnet_law (nor the machine's psim_drift) the machine's ψm is taken at 20 °C: a reader says so.
  const std::string without = std::regex_replace(std::string(kThreeNodes), std::regex("  magnet_law: [^\n]*\n"), "");
  ASSERT_NE(without, kThreeNodes);
  const ThermalConfig c = load_text(without);
  EXPECT_FALSE(c.magnet_law_stated);
  EXPECT_TRUE(c.copper_reference_stated);
  const std::vector<std::string> notes = assumed_law_notes(c, true);
  ASSERT_EQ(notes.size(), 1U);
  EXPECT_NE(notes[0].find("the magnet law takes psi_m_ref 1.14 Wb at 20 °C, an assumption"), std::string::npos) << notes[0];
  EXPECT_TRUE(assumed_law_notes(c, false).empty());  // a fit anchors the magnet law itself
  EXPECT_TRUE(load_text(kThreeNodes).magnet_law_stated);
  EXPECT_TRUE(assumed_law_notes(load_text(kThreeNodes), true).empty());
}

TEST(ThermalConfig, ANetworkWithoutProcessNoiseOnAnyNodeIsANote) {
  // Neither key on any node: both 0, the filter takes the network as exact — said. One key on one node, zero
  // included, is a statement: nothing said.
  EXPECT_TRUE(load_text(kThreeNodes).process_noise_stated);
  EXPECT_FALSE(process_noise_note(load_text(kThreeNodes)).has_value());
  const std::string without = std::regex_replace(std::string(kThreeNodes),
                                                 std::regex(", process_noise_K2_per_s: 0.001, disturbance_W2_per_s: 2"), "");
  ASSERT_NE(without, kThreeNodes);
  const ThermalConfig c = load_text(without);
  EXPECT_FALSE(c.process_noise_stated);
  EXPECT_EQ(c.fusion.filter.process_noise_K2_per_s, core::ThermalVec::Zero());
  EXPECT_EQ(c.fusion.filter.disturbance_W2_per_s, core::ThermalVec::Zero());
  const std::optional<std::string> note = process_noise_note(c);
  ASSERT_TRUE(note.has_value());
  EXPECT_NE(note->find("no node states process_noise_K2_per_s or disturbance_W2_per_s: both are 0"), std::string::npos)
      << *note;
  const std::string zero =
      std::regex_replace(without, std::regex("to_coolant_W_per_K: 95"), "to_coolant_W_per_K: 95, process_noise_K2_per_s: 0");
  EXPECT_FALSE(process_noise_note(load_text(zero)).has_value());
}

TEST(ThermalConfig, AFitsStartMayGiveTheLawsOnly) {
  test::TempFile f("laws.yaml", "thermal:\n  copper: {r_s_ref_Ohm: 0.0758, reference_C: 120}\n");
  const ThermalConfig c = load_thermal_config(f.path(), machine(), NetworkRequired::kNo);
  EXPECT_FALSE(c.has_network);
  EXPECT_DOUBLE_EQ(c.fusion.filter.network.copper.reference_C, 120.0);
  EXPECT_TRUE(c.copper_reference_stated);
  EXPECT_THROW((void)load_thermal_config(f.path(), machine()), ConfigError);  // rpemd needs the network
  // A copper map without reference_C states a scale, not where R_s was measured; the machine's rs_drift does.
  test::TempFile scale("scale.yaml", "thermal:\n  copper: {loss_scale: 0.8}\n");
  EXPECT_FALSE(load_thermal_config(scale.path(), machine(), NetworkRequired::kNo).copper_reference_stated);
  MachineConfig drifting = machine();
  drifting.rs_drift.law = core::DriftLaw{0.00393, 75.0, 0.0};
  EXPECT_TRUE(default_thermal_config(drifting).copper_reference_stated);
  EXPECT_DOUBLE_EQ(default_thermal_config(drifting).fusion.filter.network.copper.reference_C, 75.0);
  test::TempFile g("bad.yaml", "thermal:\n  losses: []\n");
  EXPECT_THROW((void)load_thermal_config(g.path(), machine(), NetworkRequired::kNo), ConfigError);
}

}  // namespace
}  // namespace rpem::io
