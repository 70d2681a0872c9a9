// The configuration loader: the paper file loads to tab_machineData / tab_psimgains; unknown keys,
// wrong types and out-of-range values are rejected with file:line.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include "rpem/core/settings.hpp"
#include "rpem/io/machine_config.hpp"
#include "support/temp_file.hpp"

namespace rpem::io {
namespace {

std::string paper_text() {
  std::ifstream in(test::source_dir() + "/config/paper-ipmsm.yaml");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Replaces the first match of `pattern` in the paper config and returns the loader's message.
std::string error_after_edit(const std::string& pattern, const std::string& replacement) {
  const std::string text =
      std::regex_replace(paper_text(), std::regex(pattern), replacement, std::regex_constants::format_first_only);
  EXPECT_NE(text, paper_text()) << "pattern did not match: " << pattern;
  test::TempFile f("cfg.yaml", text);
  try {
    (void)load_machine_config(f.path());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(MachineConfig, PaperFileMatchesThePaperTables) {
  const MachineConfig c = load_machine_config(test::source_dir() + "/config/paper-ipmsm.yaml");
  EXPECT_EQ(c.machine.rated.pole_pairs, 3);
  EXPECT_DOUBLE_EQ(c.machine.rated.voltage_ll_rms_V, 400.0);
  EXPECT_DOUBLE_EQ(c.machine.rated.current_rms_A, 4.93);
  EXPECT_DOUBLE_EQ(c.machine.r_s_Ohm, 2.25);
  EXPECT_DOUBLE_EQ(c.machine.psi_m_Wb, 1.14);
  EXPECT_DOUBLE_EQ(c.machine.l_d_H, 0.0953);
  EXPECT_DOUBLE_EQ(c.machine.l_q_H, 0.206);
  const auto& e = c.estimator;
  EXPECT_EQ(e.algorithm, core::Algorithm::kSga);
  EXPECT_DOUBLE_EQ(e.psi_m_min_speed_rpm, 100.0);
  EXPECT_DOUBLE_EQ(e.r_s_max_speed_rpm, 10.0);
  const auto& sga = e.gains[0];
  const auto& gna = e.gains[1];
  const auto& phy = e.gains[2];
  EXPECT_DOUBLE_EQ(sga.hessian[0], 6.25e-4);
  EXPECT_DOUBLE_EQ(sga.gain[0], 3.25e-4);
  EXPECT_DOUBLE_EQ(sga.hessian[1], 6.25e-4);
  EXPECT_DOUBLE_EQ(sga.gain[1], 6.25e-5);
  EXPECT_DOUBLE_EQ(gna.hessian[0], 6.25e-4);
  EXPECT_DOUBLE_EQ(gna.gain[0], 3.25e-4);
  EXPECT_DOUBLE_EQ(gna.hessian[1], 6.25e-5);
  EXPECT_DOUBLE_EQ(gna.gain[1], 7.5e-6);
  EXPECT_DOUBLE_EQ(phy.gain[0], 3.25e-4);
  EXPECT_DOUBLE_EQ(phy.gain[1], 6.25e-5);
  EXPECT_DOUBLE_EQ(e.nominal_sample_period_s, 125e-6);
  EXPECT_EQ(e.extensions.theta_offset_rad, 0.0);
}

TEST(MachineConfig, PaperFileStartsTheEstimatorAtTable1sFluxInPu) {
  // Erratum E4: the shipped configuration keeps tab_machineData's 1.14 Wb, which the estimator runs on as
  // 1.0966 pu (ψ_b = 1.03960 Wb, docs/per-unit.md), not Section VI's 0.895 pu.
  const MachineConfig c = load_machine_config(test::source_dir() + "/config/paper-ipmsm.yaml");
  const core::EstimatorConfig e =
      core::make_estimator_config(core::PerUnitBase::from_rated(c.machine.rated), c.machine, c.estimator);
  EXPECT_NEAR(e.model.psi_m_pu, 1.0966, 1e-4);
  EXPECT_NEAR(e.initial_theta_pu[core::kPsiM], 1.0966, 1e-4);
}

TEST(MachineConfig, BuiltInConfigIsThePaperFile) {
  EXPECT_EQ(builtin_paper_config_text(), paper_text());
  const MachineConfig c = builtin_paper_config();
  EXPECT_DOUBLE_EQ(c.machine.psi_m_Wb, 1.14);
}

struct BadEdit {
  const char* name;
  const char* pattern;
  const char* replacement;
  const char* expected;
};

class MalformedConfig : public ::testing::TestWithParam<BadEdit> {};

TEST_P(MalformedConfig, IsRejectedWithFileLineAndField) {
  const std::string msg = error_after_edit(GetParam().pattern, GetParam().replacement);
  EXPECT_NE(msg.find(GetParam().expected), std::string::npos) << "message: " << msg;
  EXPECT_NE(msg.find("cfg.yaml:"), std::string::npos) << "message: " << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MalformedConfig,
    ::testing::Values(
        BadEdit{"unknown_top", "\nmachine:", "\nmachnie_typo: 1\nmachine:", ":3:1: machnie_typo: unknown key"},
        BadEdit{"unknown_nested", "r_s_Ohm: 2.25", "r_s_Ohm: 2.25\n  r_s_ohm: 2.25", "machine.r_s_ohm: unknown key"},
        // A key given twice: yaml-cpp would hand the first to a lookup and drop the second silently.
        BadEdit{"duplicate_key", "r_s_Ohm: 2.25", "r_s_Ohm: 2.25\n  r_s_Ohm: 9.0",
                ":12:3: machine.r_s_Ohm: given twice in this mapping (the first would be used)"},
        BadEdit{"duplicate_flow_key", "initial: \\{psi_m_Wb: 1.14", "initial: {psi_m_Wb: 1.2, psi_m_Wb: 1.14",
                "estimator.initial.psi_m_Wb: given twice"},
        BadEdit{"out_of_range_gain", "gain: 3.25e-4", "gain: 3.25",
                "estimator.gains.sga.psi_m.gain: 3.25 is outside [0, 1]"},
        BadEdit{"negative_resistance", "r_s_Ohm: 2.25", "r_s_Ohm: -2.25", "machine.r_s_Ohm: -2.25 is outside"},
        BadEdit{"not_a_number", "l_d_H: 0.0953", "l_d_H: small", "machine.l_d_H: 'small' is not a number"},
        // C's and YAML's spellings of NaN and infinity are refused alike.
        BadEdit{"nan", "l_d_H: 0.0953", "l_d_H: nan", "machine.l_d_H: 'nan' is not finite"},
        BadEdit{"yaml_nan", "l_d_H: 0.0953", "l_d_H: .NaN", "machine.l_d_H: '.NaN' is not finite"},
        BadEdit{"yaml_minus_inf", "l_d_H: 0.0953", "l_d_H: -.inf", "machine.l_d_H: '-.inf' is not finite"},
        // A bracket left open: YAML notices it at the next line's key; the message names the line that opened it.
        BadEdit{"bracket_left_open", "l_d_H: 0.0953", "l_d_H: [0.0953",
                "YAML syntax: end of sequence flow not found (YAML notices it only here: line 13 leaves a bracket or a "
                "quote open, `l_d_H: [0.0953`)"},
        BadEdit{"bad_choice", "algorithm: sga", "algorithm: kalman",
                "estimator.algorithm: 'kalman' is not one of: sga, gna, phyint"},
        BadEdit{"missing", "    pole_pairs: 3 .*\n", "", "machine.rated.pole_pairs: required key is missing"},
        BadEdit{"fractional_pole_pairs", "pole_pairs: 3", "pole_pairs: 3.5", "'3.5' is not an integer"},
        BadEdit{"reversed_bounds", "psi_m_Wb: \\[0.57, 1.71\\]", "psi_m_Wb: [1.71, 0.57]", "min < max"},
        BadEdit{"initial_outside_bounds", "initial: \\{psi_m_Wb: 1.14", "initial: {psi_m_Wb: 2.0",
                "estimator.initial.psi_m_Wb: 2.0 is outside [0.57, 1.71]"},
        // Found by fuzz_machine_config: without estimator.initial the start is the machine's value, which D_M must hold.
        BadEdit{"default_start_outside_bounds",
                "  initial: \\{psi_m_Wb: 1.14, r_s_Ohm: 2.25\\}\n(.*\n    psi_m_Wb: )\\[0.57", "$1[1.57",
                "estimator.bounds.psi_m_Wb: excludes the estimator's start, machine.psi_m_Wb = 1.14"},
        BadEdit{"partial_initial_default_outside_bounds",
                "initial: \\{psi_m_Wb: 1.14, r_s_Ohm: 2.25\\}(\n.*\n.*\n    r_s_Ohm: )\\[1.0",
                "initial: {psi_m_Wb: 1.14}$1[2.5",
                "estimator.bounds.r_s_Ohm: excludes the estimator's start, machine.r_s_Ohm = 2.25"},
        // Found by fuzz_machine_config: a complex key escaped the reader as a yaml-cpp exception.
        BadEdit{"complex_key", "\n  sample_period_s:", "\n  ? [a, b]\n  : 1\n  sample_period_s:",
                "estimator: a key must be a name, not a list or mapping"},
        BadEdit{"scheduler_order", "r_s_max_speed_rpm: 10 ", "r_s_max_speed_rpm: 200 ",
                "must not exceed psi_m_min_speed_rpm"},
        BadEdit{"indefinite_hessian", "gna_pu: \\[1.0, 0.0, 1.0\\]", "gna_pu: [1.0, 2.0, 1.0]", "positive semi-definite"},
        BadEdit{"wrong_length", "sga_pu: \\[100.0, 100.0\\]", "sga_pu: [1.0]", "expected 2 numbers, got 1"},
        BadEdit{"bool", "psi_m: true", "psi_m: yes please", "expected true or false"},
        BadEdit{"syntax", "machine:", "machine: [", "YAML syntax"},
        BadEdit{"ext_unknown", "\nestimator:",
                "\nmodel_extensions:\n  deadtime: {t_dead_s: 1.0e-6, switching_frequency_Hz: 4000, colour: red}\nestimator:",
                "model_extensions.deadtime.colour: unknown key"},
        BadEdit{"drift_without_law", "\nestimator:", "\nmodel_extensions:\n  rs_drift: {reference_C: 20}\nestimator:",
                "a drift needs coeff_per_K or rel_change"},
        BadEdit{"delay_beyond_the_history", "\nestimator:", "\nmodel_extensions:\n  delay: {delay_s: 5.0e-4}\nestimator:",
                "model_extensions.delay.delay_s: must be below 4 sample periods"},
        BadEdit{"harmonic_unknown_key", "\nestimator:", "\nmodel_extensions:\n  flux_harmonic_6: {d_Wb: 0.01}\nestimator:",
                "model_extensions.flux_harmonic_6.d_Wb: unknown key"},
        BadEdit{"negative_r_fe",
                "\nestimator:", "\nmodel_extensions:\n  iron_loss: {r_fe_Ohm: -5}\nestimator:", "iron_loss.r_fe_Ohm"}),
    [](const auto& p) { return std::string(p.param.name); });

TEST(MachineConfig, AveragedEstimatorOptionsAreReadAndChecked) {
  EXPECT_DOUBLE_EQ(load_machine_config(test::source_dir() + "/config/paper-ipmsm.yaml").estimator.averaged.max_interval_s,
                   0.05);
  const std::string edited = std::regex_replace(
      paper_text(), std::regex("\n  floors:"),
      "\n  averaged: {max_interval_s: 0.1, inductive_correction: false, instrument_time_constant_s: 0.02}\n  floors:",
      std::regex_constants::format_first_only);
  test::TempFile f("avg.yaml", edited);
  const core::AveragedSettings a = load_machine_config(f.path()).estimator.averaged;
  EXPECT_DOUBLE_EQ(a.max_interval_s, 0.1);
  EXPECT_FALSE(a.inductive_correction);
  EXPECT_DOUBLE_EQ(a.instrument_time_constant_s, 0.02);
  EXPECT_NE(error_after_edit("\n  floors:", "\n  averaged: {max_interval_s: 0}\n  floors:").find("averaged.max_interval_s"),
            std::string::npos);
  EXPECT_NE(error_after_edit("\n  floors:", "\n  averaged: {rate: 1}\n  floors:").find("rate"), std::string::npos);
}

TEST(MachineConfig, ReportedCommandIsReadAndNeedsTheControlPeriod) {
  EXPECT_FALSE(
      load_machine_config(test::source_dir() + "/config/vesc-6374-outrunner.yaml").estimator.averaged.voltage_is_command);
  const MachineConfig firmware = load_machine_config(test::source_dir() + "/config/vesc-6374-firmware.yaml");
  EXPECT_TRUE(firmware.estimator.averaged.voltage_is_command);
  EXPECT_DOUBLE_EQ(firmware.estimator.averaged.current_sample_at, 0.5);
  EXPECT_DOUBLE_EQ(firmware.estimator.extensions.delay_s, 40e-6);
  const std::string error = error_after_edit("\n  floors:", "\n  averaged: {voltage_reported: command}\n  floors:");
  EXPECT_NE(error.find("voltage_reported"), std::string::npos) << error;
  EXPECT_NE(error.find("control_period_s"), std::string::npos) << error;
  EXPECT_NE(error_after_edit("\n  floors:", "\n  averaged: {control_period_s: 8.0e-5, voltage_reported: duty}\n  floors:")
                .find("voltage_reported"),
            std::string::npos);
}

TEST(MachineConfig, TheAnglesSourceIsReadAndChecked) {
  // The paper's drive has a position sensor (its Section I), the VESC configurations are sensorless: each file says so.
  const MachineConfig paper = load_machine_config(test::source_dir() + "/config/paper-ipmsm.yaml");
  EXPECT_FALSE(paper.estimator.regimes.sensorless);
  EXPECT_FALSE(paper.estimator.regimes.angle_source_assumed);
  for (const char* vesc : {"vesc-6374-outrunner.yaml", "vesc-6374-firmware.yaml"}) {
    const MachineConfig c = load_machine_config(test::source_dir() + "/config/" + vesc);
    EXPECT_TRUE(c.estimator.regimes.sensorless) << vesc;
    EXPECT_FALSE(c.estimator.regimes.angle_source_assumed) << vesc;
  }
  // A file that does not say it — in a regimes section, or without one — gets a sensor's frame, assumed: decided as a
  // sensor's, with the windows that rest on it flagged (core::regime_bit::kRsOnAssumedFrame) and the note.
  const std::regex stated("\n  regimes:\n    angle_source: sensor[^\n]*");
  for (const char* replacement : {"\n  regimes:\n    significance_sigma: 4", ""}) {
    const std::string edited = std::regex_replace(paper_text(), stated, replacement);
    ASSERT_NE(edited, paper_text());
    test::TempFile f("angle.yaml", edited);
    const MachineConfig c = load_machine_config(f.path());
    EXPECT_FALSE(c.estimator.regimes.sensorless) << replacement;
    EXPECT_TRUE(c.estimator.regimes.angle_source_assumed) << replacement;
    EXPECT_TRUE(core::make_regime_config(core::PerUnitBase::from_rated(c.machine.rated), c.machine, c.estimator)
                    .angle_source_assumed);
    EXPECT_NE(unstated_frame_note(c).find("say angle_source: sensorless"), std::string::npos);
  }
  EXPECT_EQ(unstated_frame_note(paper), "");
  // A sensorless frame is never an assumed one.
  core::EstimatorSettings both = paper.estimator;
  both.regimes.sensorless = both.regimes.angle_source_assumed = true;
  EXPECT_FALSE(core::make_regime_config(core::PerUnitBase::from_rated(paper.machine.rated), paper.machine, both)
                   .angle_source_assumed);
  const std::string error = error_after_edit("angle_source: sensor", "angle_source: halls");
  EXPECT_NE(error.find("estimator.regimes.angle_source: 'halls' is not one of: sensor, sensorless, hall"), std::string::npos)
      << error;
  // Hall sensors: a frame not a sensor's, bounded by their error below their speed (defaults: VESC's six states and
  // foc_sl_erpm); the two keys apply to them only and are checked.
  const auto hall = [](const std::string& keys) {
    test::TempFile f("hall.yaml",
                     std::regex_replace(paper_text(), std::regex("angle_source: sensor"), "angle_source: hall" + keys));
    return load_machine_config(f.path()).estimator.regimes;
  };
  const core::RegimeSettings defaults = hall("");
  EXPECT_TRUE(defaults.sensorless);
  EXPECT_FALSE(defaults.angle_source_assumed);
  EXPECT_DOUBLE_EQ(defaults.hall_frame_error_rad, core::kPi / 6.0);
  EXPECT_NEAR(defaults.hall_below_speed_rad_s, 209.43951, 1e-5);  // 2000 erpm
  const core::RegimeSettings given = hall("\n    hall_frame_error_rad: 0.35\n    hall_below_speed_rad_s: 400");
  EXPECT_DOUBLE_EQ(given.hall_frame_error_rad, 0.35);
  EXPECT_DOUBLE_EQ(given.hall_below_speed_rad_s, 400.0);
  EXPECT_DOUBLE_EQ(paper.estimator.regimes.hall_frame_error_rad, 0.0);
  const std::string misplaced =
      error_after_edit("angle_source: sensor", "angle_source: sensorless\n    hall_frame_error_rad: 0.5");
  EXPECT_NE(misplaced.find("estimator.regimes.hall_frame_error_rad: applies to angle_source: hall only"), std::string::npos)
      << misplaced;
  const std::string wide = error_after_edit("angle_source: sensor", "angle_source: hall\n    hall_frame_error_rad: 2");
  EXPECT_NE(wide.find("hall_frame_error_rad"), std::string::npos) << wide;
}

TEST(MachineConfig, ModelExtensionsAreRead) {
  const std::string text = paper_text() +
                           "model_extensions:\n"
                           "  deadtime: {t_dead_s: 2.0e-6, switching_frequency_Hz: 4000}\n"
                           "  theta_offset: {offset_rad: 0.05}\n"
                           "  current_offset: [{phase: b, offset_A: 0.1}]\n"
                           "  current_gain: [{phase: c, gain_error: -0.02}]\n"
                           "  delay: {delay_s: 1.0e-5}\n"
                           "  lq_saturation: {level: 1.2, curvature_per_A2: -0.001}\n"
                           "  iron_loss: {r_fe_Ohm: 2500}\n"
                           "  rs_drift: {coeff_per_K: 0.0039, reference_C: 25}\n"
                           "  psim_drift: {rel_change: -0.05}\n"
                           "  cross_saturation: {coupling_H_per_A: -0.002}\n"
                           "  flux_harmonic_6: {d_cos_Wb: 0.01, q_sin_Wb: -0.02}\n"
                           "  flux_harmonic_12: {q_cos_Wb: 0.003}\n";
  test::TempFile f("ext.yaml", text);
  const MachineConfig c = load_machine_config(f.path());
  EXPECT_DOUBLE_EQ(c.estimator.extensions.deadtime_t_dead_s, 2e-6);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.switching_frequency_Hz, 4000.0);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.theta_offset_rad, 0.05);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.current_offset_A[1], 0.1);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.current_gain_error[2], -0.02);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.delay_s, 1e-5);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.inductance_q.level, 1.2);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.inductance_q.curvature_per_A2, -0.001);
  EXPECT_TRUE(c.estimator.extensions.inductance_d.nominal());
  EXPECT_DOUBLE_EQ(c.estimator.extensions.iron_loss_r_fe_Ohm, 2500.0);
  ASSERT_TRUE(c.rs_drift.law.has_value());
  EXPECT_DOUBLE_EQ(c.rs_drift.law->coeff_per_K, 0.0039);
  EXPECT_DOUBLE_EQ(c.rs_drift.law->reference_C, 25.0);
  EXPECT_DOUBLE_EQ(c.rs_drift.law->value_ref, 0.0);  // not given: the machine's
  EXPECT_FALSE(c.psim_drift.law.has_value());
  EXPECT_DOUBLE_EQ(c.psim_drift.rel_change.value(), -0.05);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.cross_coupling_H_per_A, -0.002);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.flux_harmonics[0].d_cos_Wb, 0.01);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.flux_harmonics[0].q_sin_Wb, -0.02);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.flux_harmonics[0].d_sin_Wb, 0.0);
  EXPECT_DOUBLE_EQ(c.estimator.extensions.flux_harmonics[1].q_cos_Wb, 0.003);
}

TEST(MachineConfig, ExtensionsWrittenAsYamlReadBackToTheSameValues) {
  // What rpem diagnose writes into extended.yaml must load to exactly what it found.
  MachineConfig c = load_machine_config(test::TempFile("p.yaml", paper_text()).path());
  core::ModelExtensions& x = c.estimator.extensions;
  x.deadtime_v_err_V = 2.0647012345678;
  x.theta_offset_rad = -0.0497918;
  x.current_offset_A = core::Vec3(0.0, -0.0449122, 0.013);
  x.current_gain_error = core::Vec3(0.02, 0.0, 0.0);
  x.delay_s = 2.3 * 125e-6;  // whole periods and a fraction
  x.inductance_q = {1.2223, -0.000453337};
  x.inductance_d = {1.0, 0.0, -0.0123};
  x.iron_loss_r_fe_Ohm = 1261.24;
  x.cross_coupling_H_per_A = -0.00123456789;
  x.cross_coupling_H_per_A2 = 2.5e-5;
  x.flux_harmonics[1] = {0.0031, -0.0007, 0.0, 0.0125};
  c.rs_drift.law = core::DriftLaw{0.00391698, 25.0, 2.31};
  c.psim_drift.rel_change = -0.067;
  const std::string text =
      replace_model_extensions(paper_text() + "model_extensions:\n  delay: {delay_s: 7.77e-7}\n", model_extensions_yaml(c));
  EXPECT_EQ(text.find("7.77e-7"), std::string::npos);  // the old section is gone
  const MachineConfig back = load_machine_config(test::TempFile("x.yaml", text).path());
  const core::ModelExtensions& y = back.estimator.extensions;
  EXPECT_EQ(y.deadtime_v_err_V, x.deadtime_v_err_V);
  EXPECT_EQ(y.theta_offset_rad, x.theta_offset_rad);
  EXPECT_EQ(y.current_offset_A, x.current_offset_A);
  EXPECT_EQ(y.current_gain_error, x.current_gain_error);
  EXPECT_EQ(y.delay_s, x.delay_s);
  EXPECT_EQ(y.inductance_q.level, x.inductance_q.level);
  EXPECT_EQ(y.inductance_q.curvature_per_A2, x.inductance_q.curvature_per_A2);
  EXPECT_EQ(y.inductance_d.slope_per_A, -0.0123);
  EXPECT_EQ(y.iron_loss_r_fe_Ohm, x.iron_loss_r_fe_Ohm);
  EXPECT_EQ(y.cross_coupling_H_per_A, x.cross_coupling_H_per_A);
  EXPECT_EQ(y.cross_coupling_H_per_A2, x.cross_coupling_H_per_A2);
  EXPECT_TRUE(y.flux_harmonics[0].nominal());
  EXPECT_EQ(y.flux_harmonics[1].d_cos_Wb, 0.0031);
  EXPECT_EQ(y.flux_harmonics[1].d_sin_Wb, -0.0007);
  EXPECT_EQ(y.flux_harmonics[1].q_cos_Wb, 0.0);
  EXPECT_EQ(y.flux_harmonics[1].q_sin_Wb, 0.0125);
  ASSERT_TRUE(back.rs_drift.law.has_value());
  EXPECT_EQ(back.rs_drift.law->coeff_per_K, c.rs_drift.law->coeff_per_K);
  EXPECT_EQ(back.rs_drift.law->reference_C, 25.0);
  EXPECT_EQ(back.rs_drift.law->value_ref, 2.31);
  EXPECT_EQ(back.psim_drift.rel_change, c.psim_drift.rel_change);
  EXPECT_EQ(back.machine.r_s_Ohm, c.machine.r_s_Ohm);  // the rest of the file is kept
  EXPECT_EQ(replace_model_extensions(paper_text(), ""), paper_text());
}

// rpem diagnose's extended.yaml starts the estimator at what it calibrated: estimator.initial rewritten where the file
// gives it, as a flow map (every shipped configuration) or a block; a file without it is left as it is.
TEST(MachineConfig, TheEstimatorsStartIsReplacedWhereTheFileGivesIt) {
  const std::vector<std::pair<std::string, double>> start{{"psi_m_Wb", 1.1}, {"r_s_Ohm", 2.4}};
  const std::string flow = replace_estimator_initial(paper_text(), start, "calibrated");
  EXPECT_NE(flow.find("  initial: {psi_m_Wb: 1.1, r_s_Ohm: 2.4}  # psi_m_Wb, r_s_Ohm: calibrated (was 1.14, 2.25)"),
            std::string::npos)
      << flow;
  const MachineConfig a = load_machine_config(test::TempFile("flow.yaml", flow).path());
  EXPECT_EQ(a.estimator.initial_psi_m_Wb, 1.1);
  EXPECT_EQ(a.estimator.initial_r_s_Ohm, 2.4);
  EXPECT_EQ(a.machine.psi_m_Wb, 1.14);  // the machine's constants are replace_machine_values'

  const std::string block_text =
      std::regex_replace(paper_text(), std::regex(R"(  initial: \{psi_m_Wb: 1\.14, r_s_Ohm: 2\.25\})"),
                         "  initial:\n    r_s_Ohm: 2.25   # measured\n    psi_m_Wb: 1.14");
  ASSERT_NE(block_text, paper_text());
  const std::string block = replace_estimator_initial(block_text, start, "calibrated");
  EXPECT_NE(block.find("    r_s_Ohm: 2.4  # calibrated (was 2.25)\n    psi_m_Wb: 1.1  # calibrated (was 1.14)\n"),
            std::string::npos)
      << block;
  const MachineConfig b = load_machine_config(test::TempFile("block.yaml", block).path());
  EXPECT_EQ(b.estimator.initial_psi_m_Wb, 1.1);
  EXPECT_EQ(b.estimator.initial_r_s_Ohm, 2.4);

  const std::string none = std::regex_replace(paper_text(), std::regex(R"(  initial: \{[^}]*\}\n)"), "");
  ASSERT_NE(none, paper_text());
  EXPECT_EQ(replace_estimator_initial(none, start, "calibrated"), none);
  // Only R_s calibrated: ψm's start stays.
  const std::string one = replace_estimator_initial(paper_text(), {{"r_s_Ohm", 2.4}}, "calibrated");
  EXPECT_NE(one.find("  initial: {psi_m_Wb: 1.14, r_s_Ohm: 2.4}  # r_s_Ohm: calibrated (was 2.25)"), std::string::npos)
      << one;
}

TEST(MachineConfig, MissingFileIsAConfigError) {
  EXPECT_THROW((void)load_machine_config("/nonexistent/x.yaml"), ConfigError);
}

}  // namespace
}  // namespace rpem::io
