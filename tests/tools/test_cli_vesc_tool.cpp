// `rpem sim --vesc-tool-out` as a user runs it: the log and its truth, one line each per row; the same seed
// the same bytes; the truth one `rpem diagnose --truth` reads, through midnight; and the usage errors (exit 64)
// for what cannot be combined or parsed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

std::string rpem() { return test::binary_dir() + "/tools/rpem"; }

/// A stretch of scenarios/vesc-6374.yaml (3 s unless said) with a bridge-off second in it; the plant's ψm is
/// 0.0040 Wb throughout.
std::string scenario_text(int duration_s = 3) {
  return "name: cli-vesc-tool\nmachine: " + test::source_dir() +
         "/config/vesc-6374-outrunner.yaml\n"
         "duration_s: " +
         std::to_string(duration_s) +
         "\nwarmup_s: 0.05\nseed: 4\nsample_period_s: 80.0e-6\n"
         "inverter: {model: averaged, switching_frequency_Hz: 6250}\nplant: {step_s: 20.0e-6}\n"
         "control: {current_bandwidth_Hz: 1000}\nsensors: {current_noise_A: 0.15, current_lsb_A: 0.05}\n"
         "initial: {psi_m_Wb: 0.0040, r_s_Ohm: 0.030, speed_rpm: 2000, torque_Nm: 0.5, u_dc_V: 48}\n"
         "regimes:\n  - {t_s: 1, regime: bridge_off}\n  - {t_s: 2, regime: closed_loop}\n";
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string line; std::getline(s, line);) out.push_back(line);
  return out;
}

TEST(CliVescTool, WritesTheLogAndItsTruthRowForRow) {
  test::TempFile scenario("s.yaml", scenario_text()), log("log.csv"), truth("truth.csv"), again("again.csv");
  const std::string base = rpem() + " sim --scenario " + scenario.path() + " --vesc-tool-start 08:00:00 --vesc-tool-seed 9";
  const auto r = test::run_command(base + " --vesc-tool-out " + log.path() + " --vesc-tool-truth " + truth.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = lines(test::read_file(log.path()));
  const auto truth_rows = lines(test::read_file(truth.path()));
  ASSERT_GT(rows.size(), 25U);  // ~11 Hz for 3 s
  ASSERT_EQ(rows.size(), truth_rows.size());
  EXPECT_EQ(rows[0].rfind("ms_today;input_voltage;temp_mos_max;", 0), 0U) << rows[0];
  EXPECT_EQ(truth_rows[0].rfind("ms_today,t_s,t_start_s,", 0), 0U) << truth_rows[0];
  for (std::size_t k = 1; k < rows.size(); ++k) {
    EXPECT_EQ(std::count(rows[k].begin(), rows[k].end(), ';'), 55) << rows[k];
    const long ms = std::stol(rows[k]);
    EXPECT_EQ(ms, std::stol(truth_rows[k])) << k;  // the same row
    EXPECT_GE(ms, 8L * 3'600'000);                 // 08:00:00 UTC at t = 0
    EXPECT_LT(ms, 8L * 3'600'000 + 3'100);
  }
  EXPECT_NE(test::read_file(truth.path()).find(",bridge_off,"), std::string::npos);
  // The same seed, the same bytes.
  ASSERT_EQ(test::run_command(base + " --vesc-tool-out " + again.path()).exit_code, 0);
  EXPECT_EQ(test::read_file(log.path()), test::read_file(again.path()));
}

// The truth's `t` is the log's time as its reader unwraps ms_today (a day added at midnight), so that the truth is
// one `rpem diagnose --truth` takes (before, it had no `t` and its `regime` text was refused). On a steady-state
// log the errors are then against it: the configuration's constant ψm is off the plant's 0.0040 Wb by exactly
// what the two values say.
TEST(CliVescTool, ItsTruthIsOneDiagnoseJudgesAgainstThroughMidnight) {
  test::TempFile scenario("s.yaml", scenario_text(12)), log("log.csv"), truth("truth.csv");
  const std::string out = test::temp_path("cli_vesc_tool_diagnosis");
  std::filesystem::remove_all(out);
  const auto sim =
      test::run_command(rpem() + " sim --scenario " + scenario.path() + " --vesc-tool-start 23:59:58.500 --vesc-tool-out " +
                        log.path() + " --vesc-tool-truth " + truth.path());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const auto truth_rows = lines(test::read_file(truth.path()));
  ASSERT_GT(truth_rows.size(), 100U);
  EXPECT_EQ(truth_rows[0].substr(truth_rows[0].rfind(',')), ",t") << truth_rows[0];
  bool wrapped = false;
  for (std::size_t k = 1; k < truth_rows.size(); ++k) {
    const long ms = std::stol(truth_rows[k]);
    const double t_s = std::stod(truth_rows[k].substr(truth_rows[k].rfind(',') + 1));
    const long day_ms = ms < 86'398'500 ? 86'400'000 : 0;  // after midnight: the next day
    wrapped = wrapped || day_ms > 0;
    EXPECT_NEAR(t_s, 1e-3 * static_cast<double>(ms + day_ms), 1e-9) << truth_rows[k];
  }
  EXPECT_TRUE(wrapped);

  const auto diagnosis =
      test::run_command(rpem() + " diagnose --log " + log.path() + " --truth " + truth.path() + " --config " +
                        test::source_dir() + "/config/vesc-6374-outrunner.yaml --out " + out);
  ASSERT_EQ(diagnosis.exit_code, 0) << diagnosis.output;
  const nlohmann::json d = nlohmann::json::parse(test::read_file(out + "/diagnosis.json"));
  EXPECT_EQ(d.at("estimates_method"), "steady_state");
  EXPECT_EQ(d.at("estimates_judged_against"), "truth");
  const nlohmann::json& configured = d.at("baseline").at("estimates");
  const double psi_configured = configured.at("psi_m_Wb").get<double>();
  EXPECT_NEAR(configured.at("psi_m_error_pct").get<double>(), 100.0 * std::abs(psi_configured / 0.0040 - 1.0), 1e-6);
  EXPECT_GT(configured.at("psi_m_error_pct").get<double>(), 10.0);  // the configuration's 4.633 mWb
  std::filesystem::remove_all(out);
}

TEST(CliVescTool, WhatCannotBeCombinedOrParsedIsAUsageError) {
  test::TempFile scenario("s.yaml", scenario_text()), log("log.csv");
  const std::string base = rpem() + " sim --scenario " + scenario.path();
  for (const std::string& args :
       {" --vesc-tool-out " + log.path() + " --out " + log.path() + ".x",
        " --vesc-tool-out " + log.path() + " --truth " + log.path() + ".t", " --vesc-tool-truth " + log.path(),
        " --vesc-tool-out " + log.path() + " --vesc-tool-start 24:00:00",
        " --vesc-tool-out " + log.path() + " --vesc-tool-start 12:00",
        " --vesc-tool-out " + log.path() + " --vesc-tool-rate 500"}) {
    const auto r = test::run_command(base + args);
    EXPECT_EQ(r.exit_code, 64) << args << "\n" << r.output;
  }
}

}  // namespace
}  // namespace rpem
