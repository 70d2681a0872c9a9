// `rpem diagnose` as a user runs it (docs/diagnose.md): simulate a drive with a hidden dead time, diagnose
// the log, and carry extended.yaml into `rpem estimate` and rpemd; bad input gets a clear error and the
// documented exit code; and the worked example on the Paderborn bench data keeps its result.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/data_file.hpp"
#include "support/gnuplot_text.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

std::string rpem_tool() { return test::binary_dir() + "/tools/rpem"; }

std::string read(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// A fresh directory for one test's files (each test removes it when it passes).
std::string out_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rpem_cli_diagnose_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

/// The last r_s of an estimate CSV.
double last_r_s(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) last = line;
  std::stringstream s(last);
  double t = 0, psi = 0, r = 0;
  char comma = 0;
  s >> t >> comma >> psi >> comma >> r;
  return r;
}

TEST(CliDiagnose, FindsAHiddenDeadTimeAndTheExtendedModelCarriesIntoTheTools) {
  const std::string dir = out_dir("deadtime");
  std::string scenario = read(test::source_dir() + "/scenarios/diagnose-bench.yaml");
  const std::string anchor = "inverter: {model: switching";
  ASSERT_NE(scenario.find(anchor), std::string::npos);
  scenario.replace(scenario.find(anchor), anchor.size(), "inverter: {dead_time_s: 1.5e-6, model: switching");
  std::ofstream(dir + "/scenario.yaml") << scenario;
  const std::string log = dir + "/log.csv", truth = dir + "/truth.csv", out = dir + "/diagnosis";
  auto r = test::run_command(rpem_tool() + " sim --scenario " + dir + "/scenario.yaml --out " + log + " --truth " + truth);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  r = test::run_command(rpem_tool() + " diagnose --log " + log + " --out " + out + " --truth " + truth +
                        " --switching-frequency-Hz 4000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("effect deadtime:"), std::string::npos) << r.output;
  for (const char* f : {"report.html", "report.md", "diagnosis.json", "extended.yaml", "residual_time.png",
                        "residual_map.png", "overlay.png", "harmonics.png", "phase_sign.png", "estimates.png"}) {
    EXPECT_GT(fs::file_size(out + "/" + f), 1000U) << f;
  }
  EXPECT_EQ(test::misprinted_gnuplot_text_in(out), std::vector<std::string>{});
  const nlohmann::json d = nlohmann::json::parse(read(out + "/diagnosis.json"));
  ASSERT_EQ(d["effects"].size(), 1U) << d.dump(2);
  EXPECT_EQ(d["effects"][0]["name"], "deadtime");
  EXPECT_NEAR(d["effects"][0]["params"]["t_dead_s"].get<double>() / 1.5e-6, 1.0, 0.15);
  EXPECT_LT(d["effects"][0]["heldout_rms_after"].get<double>(), 0.1 * d["effects"][0]["heldout_rms_before"].get<double>());
  EXPECT_TRUE(d["not_identifiable"].empty());
  EXPECT_TRUE(d["effects"][0]["kept"].get<bool>());
  // The documented keys: the baseline as configured, the calibrated constants (here the configuration's
  // own, within their intervals), the noise floor and the verdict.
  EXPECT_GT(d["baseline"]["heldout_rms"].get<double>(), 0.5);
  for (const char* key : {"psi_m_Wb", "r_s_Ohm"}) {
    const auto ci = d["calibration"][std::string(key) + "_ci95"];
    ASSERT_TRUE(ci.is_array()) << key;
    EXPECT_LE(ci[0].get<double>(), d["calibration"]["configured"][key].get<double>() * 1.005) << key;
    EXPECT_GE(ci[1].get<double>(), d["calibration"]["configured"][key].get<double>() * 0.995) << key;
    EXPECT_GE(d["calibration"][std::string(key) + "_mismatch_rel"].get<double>(), 0.0) << key;
  }
  // The mismatch allowance is shown where the findings are: the terminal and the report's table.
  EXPECT_NE(r.output.find("(mismatch ±"), std::string::npos) << r.output;
  EXPECT_NE(read(out + "/report.md").find("| mismatch allowance |"), std::string::npos);
  EXPECT_TRUE(d["calibration"]["findings"].empty()) << d["calibration"].dump(2);
  EXPECT_NEAR(d["noise_floor_A"].get<double>(), 0.023, 0.003);  // σ = 0.02 A per phase: √(4/3)·σ in dq
  EXPECT_EQ(d["verdict"], "explained");
  EXPECT_LT(d["ratio"].get<double>(), 1.5);
  // With the truth given, the report judges the estimator: dead time looks like resistance at standstill.
  EXPECT_GT(d["baseline"]["estimates"]["r_s_error_pct"].get<double>(), 10.0);
  EXPECT_LT(d["extended"]["estimates"]["r_s_error_pct"].get<double>(), 1.0);

  // extended.yaml is a configuration `rpem estimate` and rpemd take as it is.
  r = test::run_command(rpem_tool() + " estimate --log " + log + " --config " + out + "/extended.yaml --out " + dir +
                        "/est_ext.csv --every 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_command(rpem_tool() + " estimate --log " + log + " --config " + test::source_dir() +
                        "/config/paper-ipmsm.yaml --out " + dir + "/est_nom.csv --every 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NEAR(last_r_s(dir + "/est_ext.csv") / 2.25, 1.0, 0.01);
  EXPECT_GT(last_r_s(dir + "/est_nom.csv") / 2.25, 1.10);
  if (fs::exists(test::binary_dir() + "/daemon/rpemd")) {
    r = test::run_command(test::binary_dir() + "/daemon/rpemd --config " + out + "/extended.yaml --check-config");
    EXPECT_EQ(r.exit_code, 0) << r.output;
  }
  fs::remove_all(dir);
}

TEST(CliDiagnose, BadInputGetsAClearErrorAndItsExitCode) {
  const std::string dir = out_dir("bad");
  std::ofstream(dir + "/bad.csv")
      << "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n0,0,0,220,1,2,3,0,0,0\n0.1,0,0,x,1,2,3,0,0,0\n";
  auto r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/bad.csv --out " + dir + "/o");
  EXPECT_EQ(r.exit_code, 65) << r.output;
  EXPECT_NE(r.output.find("bad.csv:3:4: column u_dc: 'x' is not a number"), std::string::npos) << r.output;

  std::ofstream(dir + "/cfg.yaml") << read(test::source_dir() + "/config/paper-ipmsm.yaml") << "colour: blue\n";
  std::ofstream(dir + "/short.csv") << "t,omega_el,u_d,u_q,i_d,i_q\n0,100,1,2,3,4\n";
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/short.csv --config " + dir + "/cfg.yaml --out " + dir +
                        "/o");
  EXPECT_EQ(r.exit_code, 78) << r.output;
  EXPECT_NE(r.output.find("colour: unknown key"), std::string::npos) << r.output;

  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/short.csv --out " + dir + "/o");
  EXPECT_EQ(r.exit_code, 65) << r.output;
  EXPECT_NE(r.output.find("short.csv"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("at least 80 are needed"), std::string::npos) << r.output;

  // A dead time in seconds needs u_dc, which a rotor-frame-only log may lack: refused, naming both files.
  std::ofstream(dir + "/dt.yaml") << read(test::source_dir() + "/config/paper-ipmsm.yaml")
                                  << "model_extensions:\n  deadtime: {t_dead_s: 1.0e-6, switching_frequency_Hz: 4000}\n";
  std::ofstream log(dir + "/dq.csv");
  log << "t,omega_el,u_d,u_q,i_d,i_q\n";
  for (int k = 0; k < 100; ++k) log << k * 2.5 << ",100,10,120,-1,3\n";
  log.close();
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/dq.csv --config " + dir + "/dt.yaml --out " + dir + "/o");
  EXPECT_EQ(r.exit_code, 78) << r.output;
  EXPECT_NE(r.output.find("dq.csv has no u_dc column"), std::string::npos) << r.output;

  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/dq.csv");
  EXPECT_EQ(r.exit_code, 64) << r.output;
  fs::remove_all(dir);
}

TEST(CliDiagnose, PaderbornWorkedExampleKeepsItsResult) {
  // docs/diagnose.md, "Worked example": the bench profile against the commissioned constant-parameter
  // model. Two-sided bounds, so an unexplained change either way is noticed.
  const std::string source = test::data_file("paderborn-motor-temperature/profile_A_every5th.csv");
  const std::string dir = out_dir("paderborn");
  auto r = test::run_command("python3 " + test::source_dir() + "/scripts/paderborn_to_drive_log.py " + source + " " + dir +
                             "/profile.csv --pole-pairs 4 --sample-period-s 2.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/profile.csv --config " + test::source_dir() +
                        "/config/paderborn-pmsm.yaml --out " + dir + "/diagnosis");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json d = nlohmann::json::parse(read(dir + "/diagnosis/diagnosis.json"));
  EXPECT_EQ(d["log"]["model"], "steady_state");
  EXPECT_EQ(d["log"]["excluded_idle"], 2);
  // The log's winding temperature gives the residual-against-temperature figure, whose axis names it.
  ASSERT_TRUE(fs::exists(dir + "/diagnosis/residual_temperature.gp"));
  EXPECT_EQ(test::misprinted_gnuplot_text_in(dir + "/diagnosis"), std::vector<std::string>{});
  const double baseline = d["baseline"]["heldout_rms"], extended = d["extended"]["heldout_rms"];
  EXPECT_GT(baseline, 7.5);
  EXPECT_LT(baseline, 9.5);
  // The magnet's drift is the finding; at this one speed a second, small operating-point error may pass
  // the held-out test too (docs/diagnose.md: a θ offset of −0.2°, 8 % of what is left), never a large one.
  ASSERT_GE(d["effects"].size(), 1U) << d["effects"].dump(2);
  ASSERT_LE(d["effects"].size(), 2U) << d["effects"].dump(2);
  if (d["effects"].size() == 2U) {
    EXPECT_LT(d["effects"][1]["gain_pct"].get<double>(), 15.0) << d["effects"].dump(2);
  }
  const auto& e = d["effects"][0];
  EXPECT_EQ(e["name"], "psim_drift");
  const double coeff = e["params"]["coeff_per_K"];  // NdFeB: about −0.1 %/K
  EXPECT_LT(coeff, -0.0009);
  EXPECT_GT(coeff, -0.0012);
  EXPECT_EQ(e["params"]["material"], "NdFeB");
  EXPECT_GT(e["gain_pct"].get<double>(), 60.0);  // against the calibrated baseline
  EXPECT_LT(extended, 1.5);
  EXPECT_EQ(d["calibration"]["identifiable"][0], "psi_m_Wb");
  EXPECT_GT(extended, 0.5);
  // R_s against the winding temperature would be 2.5 times copper's coefficient: never named; reported as
  // implausible where it passes the held-out test, and otherwise failing it (with L_q calibrated after the
  // magnet's drift is found, its held-out p is 0.012 > 0.01).
  for (const auto& f : d["effects"]) EXPECT_NE(f["name"], "rs_drift") << d["effects"].dump(2);
  if (!d["implausible"].empty()) {
    ASSERT_EQ(d["implausible"].size(), 1U) << d["implausible"].dump(2);
    EXPECT_EQ(d["implausible"][0]["effect"], "rs_drift");
    EXPECT_GT(d["implausible"][0]["params"]["coeff_per_K"].get<double>(), 2.0 * 0.00393);
  } else {
    bool failed_the_test = false;
    for (const auto& round : d["selection"]) {
      for (const auto& c : round) {
        if (c["effect"] == "rs_drift" && c["fitted"].get<bool>()) {
          failed_the_test = failed_the_test || c["p_value"].get<double>() > 0.01 || c["gain_pct"].get<double>() < 2.0;
        }
      }
    }
    EXPECT_TRUE(failed_the_test) << d["selection"].dump(2);
  }
  // What is left is far above the floor: said so, with where it lives.
  EXPECT_EQ(d["verdict"], "unexplained");
  EXPECT_GT(d["ratio"].get<double>(), 1.5);
  EXPECT_FALSE(d["findings"].empty());
  EXPECT_LT(d["extended"]["estimates"]["psi_m_error_pct"].get<double>(), 0.5);
  EXPECT_GT(d["baseline"]["estimates"]["psi_m_error_pct"].get<double>(), 3.0);
  fs::remove_all(dir);
}

TEST(CliDiagnose, AModelExtendedOnOneRecordingIsTheBaselineOfTheNext) {
  // docs/diagnose.md, "The configuration is the baseline": Paderborn profile A cut at the load change; the
  // heat-up extends the commissioned model (its magnet drift), and the cool-down is judged with the plain
  // configuration and with the heat-up's extended.yaml as it is. The drift law carries: the extended
  // baseline predicts the recording it never saw far better, and is reported as such.
  const std::string source = test::data_file("paderborn-motor-temperature/profile_A_every5th.csv");
  const std::string dir = out_dir("carry");
  auto r = test::run_command("python3 " + test::source_dir() + "/scripts/paderborn_to_drive_log.py " + source + " " + dir +
                             "/profile.csv --pole-pairs 4 --sample-period-s 2.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir + "/profile.csv");
  std::ofstream heat(dir + "/heatup.csv"), cool(dir + "/cooldown.csv");
  std::string line;
  for (int k = 0; std::getline(in, line); ++k) {
    if (k <= 1760) heat << line << "\n";
    if (k == 0 || k > 1760) cool << line << "\n";
  }
  heat.close();
  cool.close();
  const std::string config = test::source_dir() + "/config/paderborn-pmsm.yaml";
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/heatup.csv --config " + config + " --out " + dir +
                        "/heatup");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json a = nlohmann::json::parse(read(dir + "/heatup/diagnosis.json"));
  ASSERT_FALSE(a["effects"].empty()) << a.dump(2);
  EXPECT_EQ(a["effects"][0]["name"], "psim_drift");
  EXPECT_NE(read(dir + "/heatup/extended.yaml").find("psim_drift"), std::string::npos);
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/cooldown.csv --config " + config + " --out " + dir +
                        "/plain");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/cooldown.csv --config " + dir +
                        "/heatup/extended.yaml --out " + dir + "/carried");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json plain = nlohmann::json::parse(read(dir + "/plain/diagnosis.json"));
  const nlohmann::json carried = nlohmann::json::parse(read(dir + "/carried/diagnosis.json"));
  EXPECT_TRUE(carried["baseline"]["drift_laws_replayed"]["psim_drift"].get<bool>());
  EXPECT_FALSE(plain["baseline"]["drift_laws_replayed"]["psim_drift"].get<bool>());
  const double p = plain["baseline"]["heldout_rms"], c = carried["baseline"]["heldout_rms"];
  std::printf("cool-down baseline held-out residual: plain %.3f A, heat-up's extended.yaml %.3f A\n", p, c);
  EXPECT_LT(c, 0.5 * p);
  // The found effects add to the configuration's: the carried drift stays in the cool-down's extended.yaml.
  EXPECT_NE(read(dir + "/carried/extended.yaml").find("psim_drift"), std::string::npos);
  fs::remove_all(dir);
}

TEST(CliDiagnose, ASparseDynamicProfileHasNoNoiseFloorAndSaysWhy) {
  // Issue 23 item 5: a held-out Paderborn profile of 218 rows, all in motion, whose operating point changes
  // every third row (7.5 s) — profile A's measured rows taken in runs of three, alternately from the heat-up
  // and the cool-down, as a bench's dynamic profile sampled every 2.5 s would give them. No three
  // consecutive rows repeat an operating point and none stands still: the noise floor cannot be measured.
  // It printed "unexplained (inf times the noise floor of 0 A)" and "at standstill 0 A RMS".
  const std::string source = test::data_file("paderborn-motor-temperature/profile_A_every5th.csv");
  const std::string dir = out_dir("sparse");
  auto r = test::run_command("python3 " + test::source_dir() + "/scripts/paderborn_to_drive_log.py " + source + " " + dir +
                             "/profile.csv --pole-pairs 4 --sample-period-s 2.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> heat, cool;
  std::string header, line;
  {
    std::ifstream in(dir + "/profile.csv");
    std::getline(in, header);
    for (int k = 1; std::getline(in, line); ++k) (k <= 1760 ? heat : cool).push_back(line);
  }
  {
    std::ofstream out(dir + "/sparse.csv");
    out << header << "\n";
    for (int row = 0, run = 0; row < 218; ++run) {
      const std::vector<std::string>& from = run % 2 == 0 ? heat : cool;
      const std::size_t first = static_cast<std::size_t>(run / 2) * 21 % (from.size() - 3);
      for (std::size_t j = 0; j < 3 && row < 218; ++j, ++row) {
        const std::string& l = from[first + j];
        out << 2.5 * row << l.substr(l.find(',')) << "\n";  // t every 2.5 s, the row's measured values
      }
    }
  }
  r = test::run_command(rpem_tool() + " diagnose --log " + dir + "/sparse.csv --config " + test::source_dir() +
                        "/config/paderborn-pmsm.yaml --out " + dir + "/diagnosis");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json d = nlohmann::json::parse(read(dir + "/diagnosis/diagnosis.json"));
  EXPECT_EQ(d["log"]["samples"], 218);
  EXPECT_EQ(d["verdict"], "undetermined");
  EXPECT_TRUE(d["noise_floor_A"].is_null());
  EXPECT_TRUE(d["ratio"].is_null());
  const std::string why = d["noise_floor"]["unknown_reason"];
  EXPECT_NE(why.find("in transition between operating points"), std::string::npos) << why;
  // The reason in all three places, and never an infinite ratio or a standstill that is not there.
  EXPECT_NE(r.output.find("verdict: undetermined (noise floor unknown)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
  const std::string report = read(dir + "/diagnosis/report.md");
  EXPECT_NE(report.find("**Verdict: undetermined**"), std::string::npos);
  EXPECT_NE(report.find(why), std::string::npos);
  for (const std::string& text : {r.output, report, d.dump()}) {
    EXPECT_EQ(text.find("inf times"), std::string::npos);
    EXPECT_EQ(text.find("at standstill 0 A"), std::string::npos);
  }
  // What the log does show still stands: the magnet's drift against its temperature, found from 72 rows.
  ASSERT_FALSE(d["effects"].empty()) << d["effects"].dump(2);
  EXPECT_EQ(d["effects"][0]["name"], "psim_drift");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rpem
