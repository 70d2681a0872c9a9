// The options of `rpem` and rpemd as a user mistypes them: each mistake is refused with the exit code of its kind
// (64 a bad command line, 65 bad data, 74 an output or input that cannot be used, 78 a bad configuration) and a
// message naming the option, before anything is read or written. GIVEN a mistake WHEN the tool starts THEN it
// refuses it, and the files it names are as they were.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

const std::string kHeader = "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n";

class CliOptions : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = test::temp_path(std::string("cli_options_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    log_ = path("run.csv");
    std::ofstream out(log_);
    out << kHeader;
    for (int k = 0; k < 200; ++k) out << 125e-6 * k << ",0,0,220,1,2,-3,0.5,-0.25,-0.25\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static test::ProcessResult rpem(const std::string& args) {
    return test::run_command(test::binary_dir() + "/tools/rpem " + args);
  }
  static std::string content(const std::string& file) {
    std::ostringstream s;
    s << std::ifstream(file).rdbuf();
    return s.str();
  }

  fs::path dir_;
  std::string log_;
};

#define EXPECT_REFUSED(result, code, text)                           \
  do {                                                               \
    const test::ProcessResult r_ = (result);                         \
    EXPECT_EQ(r_.exit_code, code) << r_.output;                      \
    EXPECT_NE(r_.output.find(text), std::string::npos) << r_.output; \
  } while (false)

TEST_F(CliOptions, AFileWrittenIsNeverOneReadOrAnotherWritten) {
  // The estimate over its own log would truncate the log before reading it: refused, the log intact — by the same
  // name, through another spelling of its path, and through a link.
  const std::string before = content(log_);
  EXPECT_REFUSED(rpem("estimate --log " + log_ + " --out " + log_), 64,
                 "--out " + log_ + " names the same file as --log " + log_ + ": it would be overwritten before it is read");
  const std::string other_spelling = (dir_ / "." / "run.csv").string();
  EXPECT_REFUSED(rpem("estimate --log " + log_ + " --out " + other_spelling), 64, "names the same file as --log");
  fs::create_symlink(log_, path("link.csv"));
  EXPECT_REFUSED(rpem("estimate --log " + path("link.csv") + " --out " + log_), 64, "names the same file as --log");
  EXPECT_EQ(content(log_), before);
  // Two outputs of one run: the log and its truth into one file.
  EXPECT_REFUSED(rpem("sim --scenario " + test::source_dir() + "/scenarios/e2e-steady.yaml --out " + path("s.csv") +
                      " --truth " + path("s.csv")),
                 64,
                 "--out " + path("s.csv") + " names the same file as --truth " + path("s.csv") +
                     ": it would be "
                     "overwritten by both");
  EXPECT_FALSE(fs::exists(path("s.csv")));
  // A different file is fine, also where a number option's value happens to spell the output's name.
  const test::ProcessResult ok = rpem("estimate --log " + log_ + " --out " + path("e.csv"));
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  const std::string here = "cd " + dir_.string() + " && ";
  const test::ProcessResult number =
      test::run_command(here + test::binary_dir() + "/tools/rpem estimate --log " + log_ + " --every 2 --out 2");
  EXPECT_EQ(number.exit_code, 0) << number.output;
}

TEST_F(CliOptions, NumbersAreFinite) {
  // CLI11 reads "nan" and "inf" as numbers, and NaN passes every range check: each is refused at its option.
  EXPECT_REFUSED(rpem("diagnose --log " + log_ + " --out " + path("d") + " --max-p nan"), 64,
                 "--max-p: 'nan' is not a finite number");
  EXPECT_REFUSED(rpem("estimate --log " + log_ + " --out " + path("e.csv") + " --rate inf"), 64, "--rate: Value inf");
  EXPECT_REFUSED(rpem("thermal fit --log " + log_ + " --out " + path("t.yaml") + " --fit-until-s -nan"), 64,
                 "--fit-until-s: '-nan' is not a finite number");
  EXPECT_REFUSED(rpem("sim --scenario " + test::source_dir() + "/scenarios/e2e-steady.yaml --out " + path("s.csv") +
                      " --averaged-out " + path("a.csv") + " --averaged-rate NaN"),
                 64, "--averaged-rate: 'NaN' is not a finite number");
  // A rate whose period in ns would overflow the log's time.
  EXPECT_REFUSED(rpem("estimate --log " + log_ + " --out " + path("e.csv") + " --rate 1e-10"), 64, "--rate");
  EXPECT_FALSE(fs::exists(path("d")));
  EXPECT_FALSE(fs::exists(path("e.csv")));
  EXPECT_FALSE(fs::exists(path("s.csv")));
}

TEST_F(CliOptions, OptionsOfAnotherModeAreRefusedNotIgnored) {
  // --duration stops the emulated VESC (--vesc); `sim --out` runs the scenario whole and said nothing of it.
  EXPECT_REFUSED(
      rpem("sim --scenario " + test::source_dir() + "/scenarios/e2e-steady.yaml --out " + path("s.csv") + " --duration 0.5"),
      64, "--duration requires --vesc");
  EXPECT_FALSE(fs::exists(path("s.csv")));
  // figures: --thermal-estimate draws instead of the log's figures; --measured needs it.
  std::ofstream(path("est.csv")) << "t\n0\n";
  EXPECT_REFUSED(rpem("figures --out " + path("f") + " --thermal-estimate " + path("est.csv") + " --log " + log_), 64,
                 "--log excludes --thermal-estimate");
  EXPECT_REFUSED(rpem("figures --out " + path("f") + " --measured " + path("est.csv")), 64,
                 "--measured requires --thermal-estimate");
  // thermal fit: --nodes lays out a network where the start has none; a start with a network and --nodes conflict.
  std::ofstream(path("net.yaml")) << "thermal:\n"
                                     "  nodes:\n"
                                     "    - {name: winding, capacitance_J_per_K: 4200, to_coolant_W_per_K: 9.1}\n"
                                     "    - {name: magnet, capacitance_J_per_K: 9800, to_coolant_W_per_K: 3.2}\n"
                                     "  conductances: [{from: winding, to: magnet, W_per_K: 2.4}]\n";
  EXPECT_REFUSED(
      rpem("thermal fit --log " + log_ + " --out " + path("t.yaml") + " --start " + path("net.yaml") + " --nodes 3"), 64,
      "--nodes 3: --start " + path("net.yaml") + " has a network of 2 nodes to start from");
  EXPECT_FALSE(fs::exists(path("t.yaml")));
}

TEST_F(CliOptions, ASetCommandCarriesBothValuesAndNoOtherCommandCarriesEither) {
  // `set` replaces both initial values: one left out was sent as 0 Ω (or 0 Wb). Refused before anything is sent.
  EXPECT_REFUSED(rpem("command --seq 1 set --psi-m 0.6"), 64, "--r-s: set needs both --psi-m WB and --r-s OHM");
  EXPECT_REFUSED(rpem("command --seq 1 set --r-s 1.2"), 64, "--psi-m: set needs both");
  EXPECT_REFUSED(rpem("command --seq 1 freeze --r-s 1.2"), 64, "--r-s: is for set only, not freeze");
}

TEST_F(CliOptions, WithoutAConfigTheBuiltInMachineIsSaidToStandIn) {
  // A log of another machine is otherwise judged against the paper's ratings, whose plausibility limits name "the
  // configured machine" (a new user's VESC log refused at 3220 rad/s, 2026-12-06).
  const std::string said = "note: no --config: the built-in configuration stands for the machine";
  const test::ProcessResult without = rpem("estimate --log " + log_ + " --out " + path("e.csv"));
  EXPECT_EQ(without.exit_code, 0) << without.output;
  EXPECT_NE(without.output.find("rpem estimate: " + said), std::string::npos) << without.output;
  const test::ProcessResult with = rpem("estimate --log " + log_ + " --out " + path("e.csv") + " --config " +
                                        test::source_dir() + "/config/paper-ipmsm.yaml");
  EXPECT_EQ(with.exit_code, 0) << with.output;
  EXPECT_EQ(with.output.find(said), std::string::npos) << with.output;
}

TEST_F(CliOptions, OutputsAndInputsThatCannotBeUsedSaySo) {
  // An output directory where a file is: exit 74 (EX_IOERR) naming it, as diagnose already did.
  std::ofstream(path("f")) << "a file\n";
  EXPECT_REFUSED(rpem("figures --out " + path("f") + " --log " + log_), 74,
                 path("f") + ": cannot create the output directory");
  // A CAN interface that is not there: exit 74 naming it (it ended as an unexpected error, exit 1).
  EXPECT_REFUSED(rpem("replay " + log_ + " --can rpem_absent0"), 74, "CAN interface 'rpem_absent0' does not exist");
  // A log from a pipe: the tools read a log more than once, so it is refused by name instead of misread.
  EXPECT_REFUSED(test::run_command("cat " + log_ + " | " + test::binary_dir() +
                                   "/tools/rpem estimate --log /dev/stdin --out " + path("e.csv")),
                 74, "/dev/stdin: is not a regular file");
}

TEST_F(CliOptions, AFileIntoADirectoryThatIsNotThereIsRefusedBeforeTheWork) {
  // Before, rpem estimate read the whole log first, rpem sim --out ran as a data error (65), and only rpem thermal
  // fit checked. Now every written file's directory is checked after parsing: exit 74, nothing created.
  const std::string nowhere = path("missing") + "/out.csv";
  const std::string scenario = test::source_dir() + "/scenarios/vesc-6374.yaml";
  for (const std::string& args :
       {"estimate --log " + log_ + " --out " + nowhere, "sim --scenario " + scenario + " --out " + nowhere,
        "sim --scenario " + scenario + " --vesc-tool-out " + path("v.csv") + " --vesc-tool-truth " + nowhere,
        "thermal fit --log " + log_ + " --out " + nowhere}) {
    EXPECT_REFUSED(rpem(args), 74, nowhere + ": cannot create file: no directory " + path("missing"));
    EXPECT_FALSE(fs::exists(path("v.csv"))) << args;
  }
  // A folder of logs writes into a folder it creates, parents and all.
  fs::create_directories(path("logs"));
  fs::copy_file(log_, path("logs/run.csv"));
  const test::ProcessResult folder = rpem("estimate --log " + path("logs") + " --out " + path("new/estimates"));
  EXPECT_TRUE(fs::exists(path("new/estimates/summary.csv"))) << folder.output;
}

TEST_F(CliOptions, ATruthThatDoesNotCoverTheJudgedHalfIsBadData) {
  // diagnose --truth judges the estimates over the log's second half (here 12.5 ms to 24.9 ms): a truth must cover it,
  // increase and hold positive finite values — else it is the data's fault, exit 65 at its row.
  const auto diagnose_with = [&](const std::string& truth_rows) {
    std::ofstream(path("truth.csv")) << "t,psi_m,r_s\n" << truth_rows;
    return rpem("diagnose --log " + log_ + " --out " + path("d") + " --truth " + path("truth.csv"));
  };
  EXPECT_REFUSED(diagnose_with("1000,1.0,2.0\n1001,1.0,2.0\n"), 65,
                 path("truth.csv") +
                     ": t: the truth covers 1000.000000 to 1001.000000 s; the estimates are judged over "
                     "the log's second half");
  EXPECT_REFUSED(diagnose_with("0,1.0,2.0\n0,1.0,2.0\n"), 65, path("truth.csv") + ":3: t: the time does not increase");
  EXPECT_REFUSED(diagnose_with("0,1.0,2.0\n0.03,nan,2.0\n"), 65, path("truth.csv") + ":3");
  EXPECT_REFUSED(diagnose_with("0,1.0,2.0\n0.03,1.0,-2.0\n"), 65, path("truth.csv") + ":3: r_s: not a positive finite");
  EXPECT_REFUSED(diagnose_with("0,1.0\n"), 65, path("truth.csv") + ":2: row has 2 cells, header has 3");
  EXPECT_FALSE(fs::exists(path("d")));
}

TEST_F(CliOptions, ALogThatPausesIsCutIntoBlocksOfTheTimeItSampled) {
  // 100 rows, 1000 s without any, 100 rows: in blocks of equal duration 38 of diagnose's 40 would hold no sample
  // and the verdict would rest on the other two; in the time the log sampled (the pause left out: 1000 s is
  // 8·10⁶ median intervals of 125 µs, over the 20 that make a pause) every block holds five rows. Said before
  // anything is fitted (a truth that covers nothing stops it there).
  std::ofstream out(log_);
  out << kHeader << std::setprecision(12);
  for (int k = 0; k < 200; ++k) out << 125e-6 * k + (k >= 100 ? 1000.0 : 0.0) << ",0,0,220,1,2,-3,0.5,-0.25,-0.25\n";
  out.close();
  std::ofstream(path("truth.csv")) << "t,psi_m,r_s\n5000,1.0,2.0\n5001,1.0,2.0\n";
  const test::ProcessResult r = rpem("diagnose --log " + log_ + " --out " + path("d") + " --truth " + path("truth.csv"));
  EXPECT_EQ(r.exit_code, 65) << r.output;
  EXPECT_NE(r.output.find("note: the log's time pauses 1 time (the longest 1000 s; a pause: an interval over 20 times "
                          "the median one, 0.000125 s): the 40 training and held-out blocks are equal in the time it "
                          "sampled, the pauses left out\n"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("hold no sample"), std::string::npos) << r.output;
}

TEST_F(CliOptions, AWrappingClocksValueLiesWithinOnePeriod) {
  // VESC Tool's ms_today counts the milliseconds of one day: a value beyond a day is refused at its own row, not
  // unwrapped into a window 31 years long (or a step back reported a row later).
  // The first columns of VESC Tool's realtime header (read by name); every row at 1000 erpm with 1 A on q.
  const std::string header =
      "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
      "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
      "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;d_axis_voltage;q_axis_voltage;";
  std::ostringstream rows;
  rows << header << "\n";
  for (int k = 0; k < 20; ++k) {
    const long ms = k == 11 ? 86'400'001L : 43'200'000L + 90L * k;
    rows << ms << ";40.0;30;30;30;30;30;1.0;0.05;0.0;1.0;1000;0.05;0;0;0;0;0;0;0;0;0;0.0;0.5;\n";
  }
  std::ofstream(path("vesc.csv")) << rows.str();
  EXPECT_REFUSED(rpem("estimate --log " + path("vesc.csv") + " --config " + test::source_dir() +
                      "/config/vesc-6374-outrunner.yaml --out " + path("e.csv")),
                 65, path("vesc.csv") + ":13:1: column ms_today (t): 86400 s is outside the column's period [0, 86400) s");
}

}  // namespace
}  // namespace rpem
