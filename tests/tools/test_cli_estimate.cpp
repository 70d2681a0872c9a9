// `rpem estimate` as a user runs it: a drive log written by this test from the model (standstill
// under load, then 0.4 pu), with the machine's ψm 8 % and R_s 6 % below the configured values.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <vector>

#include "rpem/io/drive_log.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

struct LastRow {
  double t = 0, psi_m = 0, r_s = 0;
  std::size_t rows = 0;
};

LastRow read_estimates(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("t,psi_m,r_s,", 0), 0U) << line;
  LastRow r;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    char comma = 0;
    s >> r.t >> comma >> r.psi_m >> comma >> r.r_s;
    ++r.rows;
  }
  return r;
}

TEST(CliEstimate, RecoversPsiMAndRsFromADriveLog) {
  const core::PerUnitBase base = test::paper_base();
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.plant.psi_m_pu *= 0.92;
  gen.plant.r_s_pu *= 0.94;
  gen.omega_n_rad_s = base.omega_el_rad_s;
  test::TempFile log("drive.csv"), est("est.csv");
  {
    io::DriveLogWriter w(log.path(), io::DriveLogLayout{});
    std::int64_t t_ns = 0;
    const int seconds_rs = 25, seconds_psi = 8;
    gen.n_pu = 0.0;
    gen.i_ref_pu = core::mtpa_reference(gen.plant, 0.4);
    for (int k = 0; k < seconds_rs * 8000; ++k) w.write({gen.next_si(base, t_ns), {}, {}, {}});
    gen.n_pu = 0.4;
    for (int k = 0; k < seconds_psi * 8000; ++k) w.write({gen.next_si(base, t_ns), {}, {}, {}});
  }
  const std::string cmd = test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " +
                          test::source_dir() + "/config/paper-ipmsm.yaml --out " + est.path() + " --every 10";
  const test::ProcessResult r = test::run_command(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("264000 samples"), std::string::npos) << r.output;
  const LastRow last = read_estimates(est.path());
  EXPECT_EQ(last.rows, 26400U);
  EXPECT_NEAR(last.psi_m / (0.92 * 1.14), 1.0, 2e-3);
  EXPECT_NEAR(last.r_s / (0.94 * 2.25), 1.0, 2e-3);
}

TEST(CliEstimate, RateWritesOneEstimatePerPeriodOfTheLogsTime) {
  // 2 s at 8 kHz with a 0.25 s gap at 1 s: --rate 100 writes the first sample at or after each 10 ms of a
  // grid from t = 0, which restarts after the gap (docs/drive-log.md, "Estimate CSV").
  const core::PerUnitBase base = test::paper_base();
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.omega_n_rad_s = base.omega_el_rad_s;
  gen.n_pu = 0.4;
  gen.i_ref_pu = core::mtpa_reference(gen.plant, 0.4);
  test::TempFile log("drive.csv"), est("est.csv");
  {
    io::DriveLogWriter w(log.path(), io::DriveLogLayout{});
    std::int64_t t_ns = 0;
    for (int k = 0; k < 16000; ++k) {
      if (k == 8000) t_ns += 250'000'000;
      w.write({gen.next_si(base, t_ns), {}, {}, {}});
    }
  }
  const std::string rpem = test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --out " + est.path();
  test::ProcessResult r = test::run_command(rpem + " --rate 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(est.path());
  std::string line;
  std::getline(in, line);
  std::vector<double> t;
  while (std::getline(in, line)) t.push_back(std::stod(line.substr(0, line.find(','))));
  ASSERT_EQ(t.size(), 200U);  // 100 before the gap, 100 after it
  for (std::size_t j = 1; j < t.size(); ++j) {
    if (j == 100) continue;  // across the gap
    EXPECT_NEAR(t[j] - t[j - 1], 0.01, 1e-9) << j;
  }
  EXPECT_NEAR(t[100] - t[99], 0.01 + 0.25, 1e-9);
  r = test::run_command(rpem + " --rate 100 --every 80");
  EXPECT_EQ(r.exit_code, 64) << r.output;  // one decimation or the other
}

TEST(CliEstimate, BadInputExitsNonZeroWithFileAndLine) {
  test::TempFile log("bad.csv", std::string("t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n0,0,0,220,1,2,3,0,0,0\n"
                                            "0.1,0,0,220,1,2,x,0,0,0\n"));
  test::TempFile est("est.csv");
  const auto r = test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --out " + est.path());
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_NE(r.output.find("bad.csv:3:7: column u_c: 'x' is not a number"), std::string::npos) << r.output;
}

TEST(CliEstimate, BadConfigExits78) {
  test::TempFile cfg("cfg.yaml", std::string("machine: {}\n"));
  test::TempFile log("ok.csv", std::string("t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n0,0,0,220,1,2,3,0,0,0\n"));
  test::TempFile est("est.csv");
  const auto r = test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " +
                                   cfg.path() + " --out " + est.path());
  EXPECT_EQ(r.exit_code, 78);
  EXPECT_NE(r.output.find("machine.rated: required key is missing"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rpem
