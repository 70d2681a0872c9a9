// A VESC in Hall mode, as VESC Tool logs it (scenarios/vesc-tool-hall.yaml: our emulator's Hall sensors read as
// the firmware reads them, docs/scenarios.md "Hall sensors"), read by `rpem estimate` with the outrunner's file
// saying where its frame comes from. GIVEN the ride, whose frame is up to 30° off the rotor's at crawling speed
// WHEN it is estimated with `angle_source: hall` THEN ψm ends within 2 % and R_s within 5 % of the truth (issue 23's
// accuracies), and R_s adapts on more reads than a sensorless frame lets it and on no more than a sensor's would:
// the Hall bound (docs/derivations.md §13, "Hall sensors") lies between the two.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

constexpr double kPsiTrueWb = 0.0037064, kRsTrueOhm = 0.03125;  // the scenario's plant, constant

std::string rpem() { return test::binary_dir() + "/tools/rpem"; }

struct Estimated {
  double psi_m_Wb = NAN, r_s_Ohm = NAN;
  long excites_r_s = -1;  ///< the reads that excited R_s (alone or with ψm)
  std::string output;
};

/// rpem estimate on `log` with the outrunner's configuration, its angle source replaced by `source`.
Estimated estimate(const std::string& log, const std::string& source) {
  std::ifstream in(test::source_dir() + "/config/vesc-6374-outrunner.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string edited =
      std::regex_replace(text.str(), std::regex("angle_source: sensorless"), "angle_source: " + source);
  EXPECT_TRUE(source == "sensorless" || edited != text.str());
  const test::TempFile cfg("hall_" + source + ".yaml", edited), out("hall_estimates.csv");
  Estimated run;
  const test::ProcessResult r =
      test::run_command(rpem() + " estimate --log " + log + " --config " + cfg.path() + " --out " + out.path());
  run.output = r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::smatch m;
  if (std::regex_search(r.output, m, std::regex("psi_m = ([0-9.e+-]+) Wb, r_s = ([0-9.e+-]+) Ohm"))) {
    run.psi_m_Wb = std::stod(m[1]);
    run.r_s_Ohm = std::stod(m[2]);
  }
  std::smatch both, rs;
  if (std::regex_search(r.output, both, std::regex("excites_both ([0-9]+)")) &&
      std::regex_search(r.output, rs, std::regex("excites_r_s ([0-9]+)"))) {
    run.excites_r_s = std::stol(both[1]) + std::stol(rs[1]);
  }
  return run;
}

TEST(CliVescHall, AHallDrivesResultRestsOnTheSensorsBound) {
  const test::TempFile log("hall.csv"), truth("hall_truth.csv");
  const test::ProcessResult sim = test::run_command(rpem() + " sim --scenario " + test::source_dir() +
                                                    "/scenarios/vesc-tool-hall.yaml --vesc-tool-out " + log.path() +
                                                    " --vesc-tool-truth " + truth.path());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;

  // The ride holds what the bound is for: reads whose frame is well off the rotor's, none beyond a state's half.
  std::ifstream in(truth.path());
  std::string line;
  std::getline(in, line);
  std::size_t column = 0, cells = 0;
  for (std::size_t at = 0; (at = line.find(',', at)) != std::string::npos; ++at) {
    ++cells;
    if (line.compare(at + 1, 11, "frame_error") == 0) column = cells;
  }
  ASSERT_GT(column, 0U) << line;
  double worst = 0.0;
  int off = 0, rows = 0;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t c = 0; c <= column; ++c) std::getline(row, cell, ',');
    const double error = std::abs(std::stod(cell));
    worst = std::max(worst, error);
    off += error > 0.2 ? 1 : 0;  // beyond δ_tol: a frame a sensor's test would not take
    ++rows;
  }
  EXPECT_GT(off, 20) << "of " << rows;
  EXPECT_LE(worst, M_PI / 6.0 + 1e-9);

  const Estimated hall = estimate(log.path(), "hall");
  EXPECT_NEAR(hall.psi_m_Wb / kPsiTrueWb, 1.0, 0.02) << hall.output;
  const bool declared = hall.output.find("R_s not identifiable") != std::string::npos;
  if (!declared) {
    EXPECT_NEAR(hall.r_s_Ohm / kRsTrueOhm, 1.0, 0.05) << hall.output;
  }
  const Estimated sensorless = estimate(log.path(), "sensorless"), sensor = estimate(log.path(), "sensor");
  EXPECT_GT(hall.excites_r_s, sensorless.excites_r_s) << hall.output << sensorless.output;
  EXPECT_LE(hall.excites_r_s, sensor.excites_r_s) << hall.output << sensor.output;
}

}  // namespace
}  // namespace rpem
