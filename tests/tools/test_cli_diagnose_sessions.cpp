// `rpem diagnose --log FOLDER` (and `rpem figures`) as a VESC user runs it on the folder VESC Tool fills: two rides of one machine,
// logged by the independent generator (tests/independent_vesc/, its forms not ours) with clocks that overlap (both
// start at 10:00:00), diagnosed together as one machine's sessions; and what it refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

std::string rpem_tool() { return test::binary_dir() + "/tools/rpem"; }
std::string firmware_config() { return test::source_dir() + "/config/vesc-6374-firmware.yaml"; }

class CliDiagnoseSessions : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_path(std::string("cli_diagnose_sessions_") +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ + "/rides");
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// A ride of the independent generator into rides/NAME, ψm +20 % and R_s −25 % off the configuration.
  void ride(const std::string& name, int seed, int duration_s) {
    const test::ProcessResult g = test::run_command(
        test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + test::source_dir() +
        "/config/vesc-6374-outrunner.yaml --seed " + std::to_string(seed) + " --duration-s " + std::to_string(duration_s) +
        " --psi-m-rel 0.2 --r-s-rel -0.25 --start-time 10:00:00 --out " + dir_ + "/rides/" + name);
    ASSERT_EQ(g.exit_code, 0) << g.output;
  }
  [[nodiscard]] test::ProcessResult diagnose(const std::string& extra = "") const {
    return test::run_command(rpem_tool() + " diagnose --log " + dir_ + "/rides --config " + firmware_config() + " --out " +
                             dir_ + "/diag" + extra);
  }
  /// The width of ψm's calibrated 95 % interval diagnosing rides/NAME alone [Wb].
  [[nodiscard]] double psi_m_interval_alone_Wb(const std::string& name) const {
    const std::string out = dir_ + "/alone_" + name;
    const test::ProcessResult r = test::run_command(rpem_tool() + " diagnose --log " + dir_ + "/rides/" + name +
                                                    " --config " + firmware_config() + " --out " + out);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::ifstream f(out + "/diagnosis.json");
    const nlohmann::json ci = nlohmann::json::parse(f)["calibration"]["psi_m_Wb_ci95"];
    return ci[1].get<double>() - ci[0].get<double>();
  }

  std::string dir_;
};

TEST_F(CliDiagnoseSessions, TwoRidesDiagnosedTogether) {
  ride("2026-11-30_10-00-00.csv", 1, 300);
  ride("2026-12-01_10-00-00.csv", 3, 300);
  const test::ProcessResult r = diagnose();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rpem diagnose: 2 logs joined as one machine's sessions, each from the configuration"),
            std::string::npos)
      << r.output;

  std::ifstream f(dir_ + "/diag/diagnosis.json");
  const nlohmann::json d = nlohmann::json::parse(f);
  const nlohmann::json& sessions = d["log"]["sessions"];
  ASSERT_EQ(sessions.size(), 2U) << sessions.dump();
  EXPECT_EQ(sessions[0]["log"], dir_ + "/rides/2026-11-30_10-00-00.csv");
  EXPECT_EQ(sessions[1]["log"], dir_ + "/rides/2026-12-01_10-00-00.csv");
  EXPECT_EQ(sessions[0]["first_sample"], 0);
  EXPECT_EQ(sessions[1]["first_sample"], sessions[0]["samples"]);
  EXPECT_EQ(sessions[0]["samples"].get<int>() + sessions[1]["samples"].get<int>(), d["log"]["samples"].get<int>());
  // VESC Tool's clock is the time of day, 10:00 in both: the second ride follows the first, 1 s after its last row
  // (its first sample is the end of its first window, 60–1 700 ms after that).
  const double gap_s = sessions[1]["t_first_s"].get<double>() - sessions[0]["t_last_s"].get<double>();
  EXPECT_GT(gap_s, 1.0);
  EXPECT_LT(gap_s, 1.0 + 1.7);
  EXPECT_GT(sessions[0]["t_first_s"].get<double>(), 36000.0);
  for (const auto& s : sessions) EXPECT_GT(s["samples"].get<int>(), 2000) << s.dump();  // 300 s at ~11 Hz

  // Both rides are one machine whose ψm is 5.5596 mWb at 25 °C: calibrated within 2 %, as on one 600 s ride. Joining
  // does not cost precision: ψm's interval is cluster-robust over the blocks, so for two rides of equal length its
  // width is about ½·√(w_A² + w_B²) ≤ 0.71·max(w_A, w_B) (the between-ride spread of ψm adds to it), and never
  // wider than the worse ride's alone (measured on seed pairs 1/3, 2/4, 5/6, 7/8: 0.60, 0.70, 0.37, 0.75 of it).
  EXPECT_NEAR(d["calibration"]["psi_m_Wb"].get<double>() / 5.5596e-3, 1.0, 0.02);
  const nlohmann::json& ci = d["calibration"]["psi_m_Wb_ci95"];
  const double together_Wb = ci[1].get<double>() - ci[0].get<double>();
  EXPECT_LT(together_Wb, std::max(psi_m_interval_alone_Wb("2026-11-30_10-00-00.csv"),
                                  psi_m_interval_alone_Wb("2026-12-01_10-00-00.csv")));

  std::stringstream report;
  report << std::ifstream(dir_ + "/diag/report.md").rdbuf();
  EXPECT_NE(report.str().find("## Sessions"), std::string::npos);
  EXPECT_NE(report.str().find("its 2 logs joined as sessions"), std::string::npos);

  // Every figure against time marks where the second ride starts (the estimates restart from the configuration
  // there), and says so in its title; a ride diagnosed alone has no mark.
  char mark[96];
  std::snprintf(mark, sizeof mark, "set arrow from %.9g, graph 0", sessions[1]["t_first_s"].get<double>());
  for (const char* figure : {"residual_time", "regimes", "overlay", "estimates"}) {
    const std::string gp = test::read_file(dir_ + "/diag/" + figure + ".gp");
    ASSERT_FALSE(gp.empty()) << figure;
    EXPECT_NE(gp.find(mark), std::string::npos) << figure << " has no line at the second session's start (" << mark << ")";
    std::size_t lines = 0;
    for (std::size_t at = gp.find("set arrow"); at != std::string::npos; at = gp.find("set arrow", at + 1)) ++lines;
    EXPECT_EQ(lines, 1U) << figure << ": one session start, one line";
    EXPECT_NE(gp.find("(dashed: a session starts)"), std::string::npos) << figure;
  }
  for (const char* figure : {"residual_time", "regimes", "overlay", "estimates"}) {
    const std::string gp = test::read_file(dir_ + "/alone_2026-11-30_10-00-00.csv/" + figure + ".gp");
    ASSERT_FALSE(gp.empty()) << figure;
    EXPECT_EQ(gp.find("set arrow"), std::string::npos) << figure;
    EXPECT_EQ(gp.find("a session starts"), std::string::npos) << figure;
  }

  // `rpem figures` draws the folder's regimes timeline, the sessions joined as diagnose joins them.
  const test::ProcessResult fig = test::run_command(rpem_tool() + " figures --log " + dir_ + "/rides --config " +
                                                    firmware_config() + " --out " + dir_ + "/fig");
  ASSERT_EQ(fig.exit_code, 0) << fig.output;
  EXPECT_NE(fig.output.find("rpem figures: 2 logs joined as one machine's sessions"), std::string::npos) << fig.output;
  EXPECT_TRUE(fs::exists(dir_ + "/fig/regimes.png"));
}

TEST_F(CliDiagnoseSessions, RefusesWhatCannotBeJoined) {
  ride("1.csv", 1, 40);
  // A truth belongs to one log.
  const test::ProcessResult truth = diagnose(" --truth " + dir_ + "/rides/1.csv");
  EXPECT_EQ(truth.exit_code, 64) << truth.output;
  EXPECT_NE(truth.output.find("--truth is one log's truth"), std::string::npos) << truth.output;

  // A log that cannot be read ends the diagnosis with its file and line, writing nothing.
  { std::ofstream(dir_ + "/rides/2_broken.csv") << "t,i_d\n0,1\n"; }
  const test::ProcessResult broken = diagnose();
  EXPECT_EQ(broken.exit_code, 65) << broken.output;
  EXPECT_NE(broken.output.find("2_broken.csv:1"), std::string::npos) << broken.output;
  EXPECT_FALSE(fs::exists(dir_ + "/diag"));

  // Logs of two kinds (averaged windows and instantaneous samples) are not one logger's sessions.
  fs::remove(dir_ + "/rides/2_broken.csv");
  {
    std::ofstream drive(dir_ + "/rides/3_drive.csv");
    drive << "t,theta_el,omega_el,u_dc,u_d,u_q,i_d,i_q\n";
    for (int k = 0; k < 100; ++k) drive << 0.01 * k << ",0,300,40,0.5,2,-1,3\n";
  }
  const test::ProcessResult mixed = diagnose();
  EXPECT_EQ(mixed.exit_code, 65) << mixed.output;
  EXPECT_NE(mixed.output.find("3_drive.csv"), std::string::npos) << mixed.output;
  EXPECT_NE(mixed.output.find("a log of instantaneous samples, but"), std::string::npos) << mixed.output;

  // A folder without a log.
  fs::remove_all(dir_ + "/rides");
  fs::create_directories(dir_ + "/rides");
  const test::ProcessResult empty = diagnose();
  EXPECT_EQ(empty.exit_code, 74) << empty.output;
}

}  // namespace
}  // namespace rpem
