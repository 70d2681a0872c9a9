// A stalled sensorless drive whose R_s every start of the estimator agrees on, wrongly (docs/drive-log.md, "A
// voltage along the current"; eq. 12.1). GIVEN the independent VESC generator's inverted ride of seed 4, which stalls
// at about 5.7 A while its firmware alternates between open loop and the observer and the rotor rocks (±65 rad/s,
// the frame up to 180° from the rotor's: the back EMF's share along the current reads as resistance), WHEN
// `rpem estimate` reads it THEN R_s, 14.6 % high, is declared no identification by the drop along the current, though
// the runs from the bounds agree; and the same generator's seed 4 over 600 s, whose R_s meets 5 %, is not.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

struct StallRun {
  double r_s_error = 0.0;  ///< the estimate against the truth at the log's end, relative
  std::string output;
};

/// The generator's inverted ride of seed 4 over `duration_s`, estimated with config/vesc-6374-firmware.yaml;
/// `generator_options` go to the generator as they are.
StallRun inverted_ride(const std::string& duration_s, const std::string& generator_options = "") {
  const std::string name = "stall_" + duration_s + (generator_options.empty() ? "" : "_set");
  const test::TempFile log(name + ".csv"), truth(name + ".json"), estimates(name + "_estimates.csv");
  const test::ProcessResult gen =
      test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + test::source_dir() +
                        "/config/vesc-6374-outrunner.yaml --seed 4 --invert-direction --duration-s " + duration_s + " " +
                        generator_options + " --out " + log.path() + " --truth " + truth.path());
  EXPECT_EQ(gen.exit_code, 0) << gen.output;
  const test::ProcessResult r =
      test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " + test::source_dir() +
                        "/config/vesc-6374-firmware.yaml --out " + estimates.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  StallRun run;
  run.output = r.output;
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth.path()));
  std::ifstream csv(estimates.path());
  std::string line, last;
  while (std::getline(csv, line)) last = line;
  const double r_s_Ohm = std::stod(last.substr(last.find(',', last.find(',') + 1) + 1));
  run.r_s_error = r_s_Ohm / t.at("true_at_end").at("r_s_Ohm").get<double>() - 1.0;
  return run;
}

constexpr const char* kAlongCurrent = "r_s not identifiable from this log: the ";

TEST(CliVescStall, AnRsReadHighAtAStallIsDeclaredByItsDropAlongTheCurrent) {
  const StallRun stalled = inverted_ride("300");
  EXPECT_GT(stalled.r_s_error, 0.05) << stalled.output;  // the case: beyond issue 23's 5 % (seen +14.6 %)
  EXPECT_EQ(stalled.output.find("started at the ends of its bounds"), std::string::npos) << stalled.output;
  EXPECT_NE(stalled.output.find(kAlongCurrent), std::string::npos) << stalled.output;
  const StallRun longer = inverted_ride("600");
  EXPECT_LT(std::abs(longer.r_s_error), 0.05) << longer.output;  // seen +3.5 %
  EXPECT_EQ(longer.output.find(kAlongCurrent), std::string::npos) << longer.output;
}

// The stall, not the inverter: with the generator's dead time and the firmware's compensation of it both at zero the
// same ride still ends R_s beyond 5 % (seen +13.3 %), and R_s is declared no identification (there by the runs from
// the bounds, which then disagree).
TEST(CliVescStall, WithoutADeadTimeTheStallStillReadsRsHighAndItIsDeclared) {
  const StallRun run = inverted_ride("300", "--set power.t_dead_s=0 --set firmware.foc_dt_us=0");
  EXPECT_GT(run.r_s_error, 0.05) << run.output;
  EXPECT_NE(run.output.find("r_s not identifiable from this log"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace rpem
