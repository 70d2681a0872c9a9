// `rpem sim --vesc-tool-out` as a user runs it: the log and its truth, one line each per row; the same seed
// the same bytes; and the usage errors (exit 64) for what cannot be combined or parsed.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

std::string rpem() { return test::binary_dir() + "/tools/rpem"; }

/// A 3 s stretch of scenarios/vesc-6374.yaml with a bridge-off second in it.
std::string scenario_text() {
  return "name: cli-vesc-tool\nmachine: " + test::source_dir() +
         "/config/vesc-6374-outrunner.yaml\n"
         "duration_s: 3\nwarmup_s: 0.05\nseed: 4\nsample_period_s: 80.0e-6\n"
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
