// R_s adapted at standstill on a VESC's log, where a voltage the model leaves out reads as resistance from every start
// of the estimator (docs/drive-log.md, "A voltage along the current"; docs/derivations.md §12 eq. 12.1, §13 "A stall's
// rocking"). Three such voltages on the independent VESC generator, read with config/vesc-6374-firmware.yaml:
// - a sensorless stall (seed 4, inverted, 300 s): at about 5.7 A the firmware alternates between open loop and the
//   observer, the frame's error sweeps the circle and the rotor rocks; the windows whose reads show the rocking
//   excite R_s no more, and what remains is declared;
// - the same stall with no dead time at all: still high, still declared;
// - an inverter's dead time three times what the firmware compensates (seed 4, 600 s): every start agrees on R_s far
//   too high, and the drop along the current declares it;
// - a stall's onset after minutes at zero current (seed 3, inverted, 600 s): one window moves R_s, every start agrees,
//   and taking that window's step out says it decides the estimate (docs/drive-log.md, "One window decides").
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

struct Ride {
  double r_s_error = 0.0;  ///< the estimate against the truth at the log's end, relative
  std::string output;
  std::vector<std::pair<double, double>> r_s_by_t;  ///< the estimate CSV's (t, r_s) rows
};

/// The generator's ride of `seed` with `options` (duration, direction, --set), estimated with
/// config/vesc-6374-firmware.yaml.
Ride ride(int seed, const std::string& name, const std::string& options) {
  const test::TempFile log(name + ".csv"), truth(name + ".json"), estimates(name + "_estimates.csv");
  const test::ProcessResult gen =
      test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + test::source_dir() +
                        "/config/vesc-6374-outrunner.yaml --seed " + std::to_string(seed) + " " + options + " --out " +
                        log.path() + " --truth " + truth.path());
  EXPECT_EQ(gen.exit_code, 0) << gen.output;
  const test::ProcessResult r =
      test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " + test::source_dir() +
                        "/config/vesc-6374-firmware.yaml --out " + estimates.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  Ride run;
  run.output = r.output;
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth.path()));
  std::ifstream csv(estimates.path());
  std::string line;
  std::getline(csv, line);  // t,psi_m,r_s,...
  while (std::getline(csv, line))
    run.r_s_by_t.emplace_back(std::stod(line), std::stod(line.substr(line.find(',', line.find(',') + 1) + 1)));
  EXPECT_FALSE(run.r_s_by_t.empty());
  if (run.r_s_by_t.empty()) return run;
  run.r_s_error = run.r_s_by_t.back().second / t.at("true_at_end").at("r_s_Ohm").get<double>() - 1.0;
  return run;
}

Ride seed_4(const std::string& name, const std::string& options) { return ride(4, name, options); }

constexpr const char* kNotIdentifiable = "r_s not identifiable from this log";
constexpr const char* kAlongCurrent = "r_s not identifiable from this log: the ";
constexpr const char* kFromTheBounds = "started at the ends of its bounds";
constexpr const char* kOneWindow = "r_s not identifiable from this log: one window decides it";

TEST(CliVescStandstillRs, AStallsRsIsDeclaredAndALongerRideMeetsFivePercent) {
  const Ride stalled = seed_4("stall_300", "--invert-direction --duration-s 300");
  // Beyond issue 23's 5 % (seen +14.6 % before the reads' speeds entered R_s' test, +10.1 % since): declared.
  EXPECT_GT(stalled.r_s_error, 0.05) << stalled.output;
  EXPECT_NE(stalled.output.find(kNotIdentifiable), std::string::npos) << stalled.output;
  const Ride longer = seed_4("stall_600", "--invert-direction --duration-s 600");
  EXPECT_LT(std::abs(longer.r_s_error), 0.05) << longer.output;  // seen +3.5 %, +0.3 % since
  EXPECT_EQ(longer.output.find(kAlongCurrent), std::string::npos) << longer.output;
  EXPECT_EQ(longer.output.find(kOneWindow), std::string::npos) << longer.output;
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

// Seed 3's inverted 600 s ride: SGA's R_s Hessian forgets over 570 s at zero current, then one window at a stall's onset
// (−115 erpm, the current ramping to 15 A) moves R_s by −7.7 %, which the later windows leave standing: the ride ends
// beyond 5 % (seen −10.2 %) with every start agreeing, and the drop along the current within its spread. Taking that
// one window's step out moves the end by more than the 5 % asked (seen +5.9 %): declared, naming the window. The step
// the message gives is the one the estimate CSV shows at that window's t (the tool's bookkeeping of retracted windows
// against the estimator's own output).
TEST(CliVescStandstillRs, OneWindowAtAStallsOnsetThatDecidesRsIsDeclared) {
  const Ride run = ride(3, "onset_600", "--invert-direction --duration-s 600");
  EXPECT_GT(std::abs(run.r_s_error), 0.05) << run.output;
  EXPECT_EQ(run.output.find(kFromTheBounds), std::string::npos) << run.output;
  const std::size_t at = run.output.find(kOneWindow);
  ASSERT_NE(at, std::string::npos) << run.output;
  double t_s = 0.0, erpm = 0.0, current_A = 0.0, moved_pct = 0.0, without_Ohm = 0.0, from_pct = 0.0, ends_Ohm = 0.0;
  ASSERT_EQ(std::sscanf(run.output.c_str() + at,
                        "r_s not identifiable from this log: one window decides it: the window ending at t = %lf s (the "
                        "estimate CSV's t; %lf erpm, %lf A) moved it by %lf %%, and without that step the estimator "
                        "ends at %lf Ohm, %lf %% from the %lf Ohm",
                        &t_s, &erpm, &current_A, &moved_pct, &without_Ohm, &from_pct, &ends_Ohm),
            7)
      << run.output.substr(at);
  EXPECT_GT(std::abs(from_pct), 5.0);
  EXPECT_NEAR(from_pct, 100.0 * (without_Ohm / ends_Ohm - 1.0), 0.06);
  EXPECT_NEAR(ends_Ohm, run.r_s_by_t.back().second, 2e-5 * ends_Ohm);  // printed to five digits
  // The window's step in the estimate CSV: its row's r_s against the row before it.
  std::size_t row = 0;
  while (row < run.r_s_by_t.size() && std::abs(run.r_s_by_t[row].first - t_s) > 5e-4) ++row;
  ASSERT_LT(row, run.r_s_by_t.size()) << "no row at t = " << t_s;
  ASSERT_GT(row, 0U);
  const double csv_step = run.r_s_by_t[row].second - run.r_s_by_t[row - 1].second;
  EXPECT_NEAR(moved_pct, 100.0 * csv_step / ends_Ohm, 0.06);
  EXPECT_GT(std::abs(moved_pct), 5.0);  // a step above the accuracy asked: only such a window can decide alone
}

}  // namespace
}  // namespace rpem
