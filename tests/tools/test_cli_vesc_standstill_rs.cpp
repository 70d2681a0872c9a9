// R_s adapted at standstill on a VESC's log, where a voltage the model leaves out reads as resistance from every start
// of the estimator (docs/drive-log.md, "A voltage along the current"; docs/derivations.md §12 eq. 12.1, §13 "A stall's
// rocking"). Three such voltages on the independent VESC generator, read with config/vesc-6374-firmware.yaml:
// - a sensorless stall (seed 4, inverted, 300 s): at about 5.7 A the firmware alternates between open loop and the
//   observer, the frame's error sweeps the circle and the rotor rocks; the windows whose reads show the rocking
//   excite R_s no more, and what remains is declared;
// - the same stall with no dead time at all: still high, still declared;
// - an inverter's dead time three times what the firmware compensates (seed 4, 600 s): every start agrees on R_s far
//   too high, and the drop along the current declares it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

struct Ride {
  double r_s_error = 0.0;  ///< the estimate against the truth at the log's end, relative
  std::string output;
};

/// The generator's ride of seed 4 with `options` (duration, direction, --set), estimated with
/// config/vesc-6374-firmware.yaml.
Ride seed_4(const std::string& name, const std::string& options) {
  const test::TempFile log(name + ".csv"), truth(name + ".json"), estimates(name + "_estimates.csv");
  const test::ProcessResult gen = test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " +
                                                    test::source_dir() + "/config/vesc-6374-outrunner.yaml --seed 4 " +
                                                    options + " --out " + log.path() + " --truth " + truth.path());
  EXPECT_EQ(gen.exit_code, 0) << gen.output;
  const test::ProcessResult r =
      test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " + test::source_dir() +
                        "/config/vesc-6374-firmware.yaml --out " + estimates.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  Ride run;
  run.output = r.output;
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth.path()));
  std::ifstream csv(estimates.path());
  std::string line, last;
  while (std::getline(csv, line)) last = line;
  const double r_s_Ohm = std::stod(last.substr(last.find(',', last.find(',') + 1) + 1));
  run.r_s_error = r_s_Ohm / t.at("true_at_end").at("r_s_Ohm").get<double>() - 1.0;
  return run;
}

constexpr const char* kNotIdentifiable = "r_s not identifiable from this log";
constexpr const char* kAlongCurrent = "r_s not identifiable from this log: the ";
constexpr const char* kFromTheBounds = "started at the ends of its bounds";

TEST(CliVescStandstillRs, AStallsRsIsDeclaredAndALongerRideMeetsFivePercent) {
  const Ride stalled = seed_4("stall_300", "--invert-direction --duration-s 300");
  // Beyond issue 23's 5 % (seen +14.6 % before the reads' speeds entered R_s' test, +10.1 % since): declared.
  EXPECT_GT(stalled.r_s_error, 0.05) << stalled.output;
  EXPECT_NE(stalled.output.find(kNotIdentifiable), std::string::npos) << stalled.output;
  const Ride longer = seed_4("stall_600", "--invert-direction --duration-s 600");
  EXPECT_LT(std::abs(longer.r_s_error), 0.05) << longer.output;  // seen +3.5 %, +0.3 % since
  EXPECT_EQ(longer.output.find(kAlongCurrent), std::string::npos) << longer.output;
}

// The stall, not the inverter: with the generator's dead time and the firmware's compensation of it both at zero the
// same ride still ends R_s beyond 5 % (seen +13.3 %), and R_s is declared no identification.
TEST(CliVescStandstillRs, WithoutADeadTimeTheStallStillReadsRsHighAndItIsDeclared) {
  const Ride run = seed_4("stall_no_dead_time",
                          "--invert-direction --duration-s 300 --set power.t_dead_s=0 --set "
                          "firmware.foc_dt_us=0");
  EXPECT_GT(run.r_s_error, 0.05) << run.output;
  EXPECT_NE(run.output.find(kNotIdentifiable), std::string::npos) << run.output;
}

// A dead time of 0.48 µs against the 0.16 µs the firmware's foc_dt_us = 0.12 µs compensates (tests/independent_vesc,
// case.cpp): 0.32 µs·12.5 kHz·48 V = 0.19 V per leg left along the current. Both starts end near the same high value,
// so only the drop along the current can tell (eq. 12.1).
TEST(CliVescStandstillRs, AnUncompensatedDeadTimeIsDeclaredByItsDropAlongTheCurrent) {
  const Ride run = seed_4("dead_time", "--duration-s 600 --set power.t_dead_s=4.8e-7");
  EXPECT_GT(run.r_s_error, 0.10) << run.output;  // seen +32.8 %
  EXPECT_EQ(run.output.find(kFromTheBounds), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(kAlongCurrent), std::string::npos) << run.output;
}

}  // namespace
}  // namespace rpem
