// Every `rpem` subcommand that reads a drive log, as a user runs it: a log with a header and no rows, and
// a log with a value no drive produces, are refused with exit 65 (EX_DATAERR) and a message naming the
// file, line and column. GIVEN such a log WHEN each tool reads it THEN none of them runs on it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

const std::string kHeader = "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n";

struct Tool {
  const char* name;
  /// The command line with LOG and OUT for the log and an output path.
  std::string command;
};

void PrintTo(const Tool& t, std::ostream* os) { *os << t.name; }

class EveryToolReadingADriveLog : public ::testing::TestWithParam<Tool> {
 protected:
  void SetUp() override {
    dir_ = test::temp_path(std::string("cli_drive_log_") + GetParam().name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs the tool on a log holding `content`.
  test::ProcessResult run_on(const std::string& file, const std::string& content) const {
    const std::string log = (dir_ / file).string();
    std::ofstream(log) << content;
    std::string cmd = GetParam().command;
    cmd.replace(cmd.find("LOG"), 3, log);
    cmd.replace(cmd.find("OUT"), 3, (dir_ / "out").string());
    return test::run_command(test::binary_dir() + "/tools/rpem " + cmd);
  }

  fs::path dir_;
};

TEST_P(EveryToolReadingADriveLog, RefusesALogWithoutSamples) {
  const test::ProcessResult r = run_on("header_only.csv", kHeader);
  EXPECT_EQ(r.exit_code, 65) << r.output;
  EXPECT_NE(r.output.find("header_only.csv:1: no samples"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("psi_m ="), std::string::npos) << r.output;  // no estimate printed
}

TEST_P(EveryToolReadingADriveLog, RefusesAValueNoDriveProduces) {
  const test::ProcessResult r = run_on("huge.csv", kHeader + "0,0,0,220,1e308,2,3,0,0,0\n");
  EXPECT_EQ(r.exit_code, 65) << r.output;
  EXPECT_NE(r.output.find("huge.csv:2:5: column u_a: 1e+308 V is beyond the plausible"), std::string::npos) << r.output;
}

INSTANTIATE_TEST_SUITE_P(Tools, EveryToolReadingADriveLog,
                         ::testing::Values(Tool{"estimate", "estimate --log LOG --out OUT"},
                                           Tool{"diagnose", "diagnose --log LOG --out OUT"},
                                           Tool{"replay", "replay LOG --candump OUT"},
                                           Tool{"thermal_fit", "thermal fit --log LOG --out OUT"}),
                         [](const auto& p) { return std::string(p.param.name); });

TEST(CliDriveLog, ToolsThatKnowTheMachineHoldCurrentsToTenTimesItsRating) {
  // The built-in paper machine: 10·I_b = 10·√2·4.93 A = 69.7 A; 100 A is refused by the tools that know
  // the machine (estimate, diagnose, thermal fit) and passed on by replay, which does not.
  const fs::path dir = test::temp_path("cli_drive_log_machine");
  fs::create_directories(dir);
  const std::string log = (dir / "amps.csv").string();
  std::ofstream(log) << kHeader << "0,0,0,220,1,2,3,0,100,-100\n";
  for (const std::string& sub : {"estimate --log " + log + " --out " + (dir / "est.csv").string(),
                                 "diagnose --log " + log + " --out " + (dir / "d").string(),
                                 "thermal fit --log " + log + " --out " + (dir / "t.yaml").string()}) {
    const test::ProcessResult r = test::run_command(test::binary_dir() + "/tools/rpem " + sub);
    EXPECT_EQ(r.exit_code, 65) << sub << "\n" << r.output;
    EXPECT_NE(r.output.find("amps.csv:2:9: column i_b: 100 A is beyond the plausible ±69.7207 A (10 x the configured "
                            "machine's rated peak phase current 6.972 A"),
              std::string::npos)
        << sub << "\n"
        << r.output;
  }
  const test::ProcessResult r =
      test::run_command(test::binary_dir() + "/tools/rpem replay " + log + " --candump " + (dir / "frames.log").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  fs::remove_all(dir);
}

TEST(CliDriveLog, ToolsThatNeedALongerLogSaySoWithTheDataErrorsExit) {
  // Five valid rows (125 µs apart): estimate and figures run on them; diagnose's blocks and thermal fit's filter steps need more,
  // which is the log's fault, not the program's — exit 65 (EX_DATAERR) naming the file, as any bad log.
  const fs::path dir = test::temp_path("cli_drive_log_short");
  fs::create_directories(dir);
  const std::string log = (dir / "short.csv").string();
  const auto write_rows = [&](int rows, double dt_s) {
    std::ofstream out(log);
    out << kHeader;
    for (int k = 0; k < rows; ++k) out << dt_s * k << ",0,0,220,1,2,-3,0.5,-0.25,-0.25\n";
  };
  const auto rpem = [&](const std::string& tool, const std::string& out) {
    return test::run_command(test::binary_dir() + "/tools/rpem " + tool + " --log " + log + " --out " +
                             (dir / out).string());
  };
  write_rows(5, 125e-6);
  const test::ProcessResult e = rpem("estimate", "e.csv");
  EXPECT_EQ(e.exit_code, 0) << e.output;
  const test::ProcessResult d = rpem("diagnose", "d");
  EXPECT_EQ(d.exit_code, 65) << d.output;
  EXPECT_NE(
      d.output.find("short.csv: the log gives 5 samples; at least 80 are needed (40 training and held-out blocks, 2 each)"),
      std::string::npos)
      << d.output;
  // rpem figures draws the regime timeline of the same five rows (it splits no blocks).
  const test::ProcessResult f = rpem("figures", "f");
  EXPECT_EQ(f.exit_code, 0) << f.output;
  EXPECT_TRUE(fs::exists(dir / "f" / "regimes.png")) << f.output;
  const test::ProcessResult t = rpem("thermal fit", "t.yaml");
  EXPECT_EQ(t.exit_code, 65) << t.output;
  EXPECT_NE(t.output.find("short.csv: the log gives 0 steps of the thermal filter; a fit needs at least 10"),
            std::string::npos)
      << t.output;
  EXPECT_FALSE(fs::exists(dir / "t.yaml"));
  // 15 s of rows: enough filter steps (1 s each), but not before a training part's end at 3 s.
  write_rows(151, 0.1);
  // The option's fault, not the log's: a usage error (64), the log's span said.
  const test::ProcessResult u = rpem("thermal fit --fit-until-s 3", "t.yaml");
  EXPECT_EQ(u.exit_code, 64) << u.output;
  EXPECT_NE(u.output.find("rpem thermal fit: --fit-until-s 3: "), std::string::npos) << u.output;
  EXPECT_NE(u.output.find(" end by then, a fit needs at least 10; "), std::string::npos) << u.output;
  EXPECT_NE(u.output.find("short.csv's steps end from 1"), std::string::npos) << u.output;
  EXPECT_FALSE(fs::exists(dir / "t.yaml"));
  // 12 s of rows: 10 steps or more, but fewer in the default training part (its first 75 %): the log's fault (65),
  // and the message names the default, not an option that was not given.
  write_rows(121, 0.1);
  const test::ProcessResult w = rpem("thermal fit", "t.yaml");
  EXPECT_EQ(w.exit_code, 65) << w.output;
  EXPECT_NE(w.output.find("short.csv: fewer than 10 steps of the thermal filter end by the training part's end (the "
                          "first 75 % of the log, to "),
            std::string::npos)
      << w.output;
  // Three rows are too few for figures' timeline too; it says what for, not diagnose's blocks, which it does not cut.
  write_rows(3, 125e-6);
  const test::ProcessResult g = rpem("figures", "g");
  EXPECT_EQ(g.exit_code, 65) << g.output;
  EXPECT_NE(g.output.find("short.csv: the log gives 3 samples; at least 4 are needed (for a timeline"), std::string::npos)
      << g.output;
  EXPECT_EQ(g.output.find("training and held-out"), std::string::npos) << g.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rpem
