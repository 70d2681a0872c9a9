// `rpem diagnose` on VESC Tool logs as a user runs it: the emulated field ride (`rpem sim --vesc-tool-out`,
// scenarios/vesc-tool-field.yaml; config/vesc-6374-outrunner.yaml, the emulator reports the period's mean
// voltage) and the two logs of the independent generator (tests/independent_vesc/, its truth only;
// config/vesc-6374-firmware.yaml, the firmware's command, docs/drive-log.md), each off its configuration by 15–25 %. ψm is calibrated within
// 2 % of the generator's truth, and the diagnosis says what it excluded (counts per regime, the rule and its
// key) on stderr, in diagnosis.json and in the report (issue 23 item 6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

std::string rpem_tool() { return test::binary_dir() + "/tools/rpem"; }
std::string outrunner_config() { return test::source_dir() + "/config/vesc-6374-outrunner.yaml"; }
std::string firmware_config() { return test::source_dir() + "/config/vesc-6374-firmware.yaml"; }

/// The rest of the first line of `output` after `prefix` ("" if none).
std::string line_after(const std::string& output, const std::string& prefix) {
  const std::size_t at = output.find(prefix);
  if (at == std::string::npos) return "";
  const std::size_t from = at + prefix.size();
  return output.substr(from, output.find('\n', from) - from);
}

class VescToolLogs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        test::temp_path(std::string("cli_diagnose_vesc_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Diagnoses `log`; checks what every diagnosis of such a log must say, returns diagnosis.json.
  nlohmann::json diagnose(const std::string& log, const std::string& config) {
    const std::string out = dir_ + "/diag";
    const test::ProcessResult r =
        test::run_command(rpem_tool() + " diagnose --log " + log + " --config " + config + " --out " + out);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("voltages reported as the drive's command, turned into the applied mean (by −1·ω·T_c") !=
                  std::string::npos,
              config == firmware_config())
        << r.output;
    EXPECT_NE(r.output.find("rpem diagnose: regimes: "), std::string::npos) << r.output;
    // One classification for every consumer (issue 23, item 2): rpem estimate counts the same samples in each regime.
    // (Before 2026-12-04 diagnose classified the windows without the reader's speed error, and counted 40 % fewer
    // transient windows on a user's log than estimate.)
    const test::ProcessResult e = test::run_command(rpem_tool() + " estimate --log " + log + " --config " + config +
                                                    " --out " + dir_ + "/estimate.csv");
    EXPECT_EQ(e.exit_code, 0) << e.output;
    EXPECT_EQ(line_after(r.output, "rpem diagnose: regimes: "), line_after(e.output, "rpem estimate: regimes: "))
        << r.output << e.output;
    std::ifstream f(out + "/diagnosis.json");
    nlohmann::json d = nlohmann::json::parse(f);
    // What was excluded and why: counts per regime, and a rule with its keys for each that took over a tenth.
    const nlohmann::json& regimes = d["log"]["regimes"];
    int excluded = 0;
    for (const char* k : {"transient", "not_locked", "bridge_off", "invalid"}) excluded += regimes[k].get<int>();
    EXPECT_GT(excluded, 0) << regimes.dump();
    for (const auto& why : d["log"]["exclusion_explanations"]) {
      const std::string s = why;
      EXPECT_NE(s.find("Keys:"), std::string::npos) << s;
      EXPECT_NE(r.output.find(s), std::string::npos) << r.output;
    }
    std::stringstream report;
    report << std::ifstream(out + "/report.md").rdbuf();
    EXPECT_NE(report.str().find("## Regimes"), std::string::npos);
    EXPECT_TRUE(fs::exists(out + "/regimes.png"));
    std::printf("%s: regimes %s; psi_m %.6g Wb\n", log.c_str(), regimes.dump().c_str(),
                d["calibration"]["psi_m_Wb"].get<double>());
    return d;
  }

  std::string dir_;
};

/// "The estimator with the extended model" on a log of averaged windows: the ψm each row implies (where the data's
/// noise determines it) against what each model assumes, as the median relative error. The extended model
/// carries the calibrated ψm, so its rows' median error is within the 2 % the calibration is held to; the
/// configuration's is its known offset from the truth, |ψ_configured/ψ_true − 1|, within the same 2 points.
/// (Before rows were judged by their noise and the median taken, one transient row implying 2.6 Wb made the
/// calibrated model's "error" 26 %.)
void expect_implied_psi_m(const nlohmann::json& d, double psi_true_Wb) {
  const double configured = d["calibration"]["configured"]["psi_m_Wb"];
  ASSERT_TRUE(d["extended"]["estimates"]["psi_m_error_pct"].is_number()) << d["extended"].dump();
  EXPECT_LT(d["extended"]["estimates"]["psi_m_error_pct"].get<double>(), 2.0);
  EXPECT_NEAR(d["baseline"]["estimates"]["psi_m_error_pct"].get<double>(), 100.0 * std::abs(configured / psi_true_Wb - 1.0),
              2.0);
}

/// The independent generator's log and its truth ψm at 25 °C (`indep_vesc_log` prints it; the truth file
/// holds it per row).
std::string independent_log(const std::string& dir, const std::string& args) {
  const std::string log = dir + "/indep.csv";
  const test::ProcessResult g = test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " +
                                                  outrunner_config() + " --duration-s 600 " + args + " --out " + log);
  EXPECT_EQ(g.exit_code, 0) << g.output;
  return log;
}

TEST_F(VescToolLogs, IndependentGeneratorSeed1) {
  // ψm +20 %, R_s −25 %, the firmware's measured back EMF while the bridge is off: true ψm 5.5596 mWb.
  const nlohmann::json d = diagnose(independent_log(dir_, "--seed 1 --psi-m-rel 0.2 --r-s-rel -0.25"), firmware_config());
  EXPECT_NEAR(d["calibration"]["psi_m_Wb"].get<double>() / 5.5596e-3, 1.0, 0.02);
  expect_implied_psi_m(d, 5.5596e-3);
}

TEST_F(VescToolLogs, IndependentGeneratorSeed2ZerosWhileOffAcrossMidnight) {
  // ψm −15 %, R_s +20 %, zeros while the bridge is off (the field log's kind), across midnight: 3.938 mWb.
  const nlohmann::json d = diagnose(
      independent_log(dir_, "--seed 2 --psi-m-rel -0.15 --r-s-rel 0.2 --off-voltage zero --midnight"), firmware_config());
  EXPECT_NEAR(d["calibration"]["psi_m_Wb"].get<double>() / 3.93805e-3, 1.0, 0.02);
  expect_implied_psi_m(d, 3.93805e-3);
}

TEST_F(VescToolLogs, IndependentGeneratorInVescTool117sHeaderWithoutDqVoltages) {
  // Seed 3 (ψm 5.4800 mWb, R_s 0.03080 Ohm at the end) as VESC Tool 1.17 wrote it: no d/q voltages, rebuilt from the
  // duty cycle (docs/drive-log.md, "Logs without d/q values"). A magnitude carries no back-EMF direction, so with the
  // sensorless frame no lock test excludes the open-loop start-ups, where R_s and a voltage along the current are
  // excited; and u_d is the configured L_q's own. Before 2026-12-04 diagnose calibrated R_s 0.0239 Ohm with a 95 %
  // interval of [0.0222, 0.0256] (22 % low, the truth outside it) and L_q to its configured value within 0.014 %;
  // rpem estimate declared R_s not identifiable on the same log.
  const std::string log = independent_log(dir_, "--seed 3 --header-version 1");
  const nlohmann::json d = diagnose(log, outrunner_config());
  EXPECT_NEAR(d["calibration"]["psi_m_Wb"].get<double>() / 5.4800e-3, 1.0, 0.02);
  const nlohmann::json& identifiable = d["calibration"]["identifiable"];
  for (const char* withheld : {"r_s_Ohm", "l_q_H"}) {
    EXPECT_EQ(std::find(identifiable.begin(), identifiable.end(), withheld), identifiable.end()) << identifiable.dump();
  }
  for (const auto& e : d["effects"]) {
    EXPECT_NE(e["name"], "deadtime");
    EXPECT_NE(e["name"], "rs_drift");
  }
  bool r_s_said = false;
  for (const auto& u : d["not_identifiable"]) {
    const std::vector<std::string> names = u["effects"];
    if (names.front() != "r_s_Ohm") continue;
    r_s_said = true;
    EXPECT_EQ(names, (std::vector<std::string>{"r_s_Ohm", "deadtime", "rs_drift"}));
    EXPECT_NE(u["reason"].get<std::string>().find("no back-EMF direction"), std::string::npos) << u.dump();
  }
  EXPECT_TRUE(r_s_said) << d["not_identifiable"].dump();
}

TEST_F(VescToolLogs, AFolderMixingLoggedAndRebuiltVoltagesIsCalibratedFromTheLoggedSessions) {
  // One machine's rides before and after a VESC Tool update: seed 3 of the independent generator in the 1.20 header
  // (d/q voltages logged) and in 1.17's (rebuilt from the duty cycle, u_d the configuration's R_s·i_d − ω·L_q·i_q).
  // The rebuilt session is left out, and said so with its file; nothing is withheld for it, since the logged session
  // carries R_s and L_q: the calibration is the logged session's alone. Before 2026-12-04 one rebuilt session withheld
  // R_s and L_q from the whole folder, and on a user's folder the configured R_s' error (17 %) was then named as a
  // cross-saturation effect and written into extended.yaml.
  const std::string generator = test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " +
                                outrunner_config() + " --duration-s 600 --seed 3 ";
  for (const char* folder : {"/mixed", "/logged"}) fs::create_directories(dir_ + folder);
  for (const std::string& out : {dir_ + "/mixed/2026-11-30_09-05-10.csv", dir_ + "/logged/2026-11-30_09-05-10.csv"}) {
    ASSERT_EQ(test::run_command(generator + "--out " + out).exit_code, 0);
  }
  const std::string rebuilt = dir_ + "/mixed/2026-12-01_10-00-00.csv";
  ASSERT_EQ(test::run_command(generator + "--header-version 1 --out " + rebuilt).exit_code, 0);
  auto diagnose_folder = [&](const std::string& folder) {
    const test::ProcessResult r = test::run_command(rpem_tool() + " diagnose --log " + dir_ + folder + " --config " +
                                                    firmware_config() + " --out " + dir_ + folder + "_diag");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::ifstream f(dir_ + folder + "_diag/diagnosis.json");
    return std::make_pair(r.output, nlohmann::json::parse(f));
  };
  const auto [said, mixed] = diagnose_folder("/mixed");
  const auto [said_alone, logged] = diagnose_folder("/logged");
  EXPECT_NE(said.find("6594 of 13188 rows (50.0 %) were left out: they are the sessions whose voltages are rebuilt "
                      "from the duty cycle (" +
                      rebuilt + ")"),
            std::string::npos)
      << said;
  for (const auto& u : mixed["not_identifiable"]) {
    const std::string first = u["effects"].front();
    EXPECT_TRUE(first != "r_s_Ohm" && first != "l_q_H") << u.dump();
  }
  EXPECT_EQ(mixed["calibration"]["identifiable"], logged["calibration"]["identifiable"]);
  EXPECT_EQ(mixed["effects"].size(), logged["effects"].size()) << mixed["effects"].dump();
  // The same rows fitted; the blocks are cut in the folder's sampled time, so the split differs a little.
  EXPECT_NEAR(mixed["calibration"]["psi_m_Wb"].get<double>() / logged["calibration"]["psi_m_Wb"].get<double>(), 1.0, 0.005);
  EXPECT_NEAR(mixed["calibration"]["psi_m_Wb"].get<double>() / 5.4800e-3, 1.0, 0.02);
}

TEST_F(VescToolLogs, EmulatedFieldRide) {
  // The plant's ψm 3.7064 mWb (−20 %) at a constant 20 °C (scenarios/vesc-tool-field.yaml).
  const std::string log = dir_ + "/field.csv";
  const test::ProcessResult s = test::run_command(rpem_tool() + " sim --scenario " + test::source_dir() +
                                                  "/scenarios/vesc-tool-field.yaml --vesc-tool-out " + log);
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const nlohmann::json d = diagnose(log, outrunner_config());
  EXPECT_NEAR(d["calibration"]["psi_m_Wb"].get<double>() / 3.7064e-3, 1.0, 0.02);
  EXPECT_GT(d["log"]["regimes"]["bridge_off"].get<int>(), 300);  // 45 s released with zeros reported at 11 Hz
  expect_implied_psi_m(d, 3.7064e-3);
  // The emulated VESC holds i_d at 0 and VESC Tool writes it to 10 mA: no row determines R_s = (u_d + ω·L_q·i_q)/i_d,
  // so no error is stated against it (it was 100 %).
  EXPECT_TRUE(d["extended"]["estimates"]["r_s_error_pct"].is_null()) << d["extended"]["estimates"].dump();
}

}  // namespace
}  // namespace rpem
