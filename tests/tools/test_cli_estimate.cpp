// `rpem estimate` as a user runs it: a drive log written by this test from the model (standstill
// under load, then 0.4 pu), with the machine's ψm 8 % and R_s 6 % below the configured values.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

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
    for (int k = 0; k < seconds_rs * 8000; ++k) w.write({gen.next_si(base, t_ns), {}, {}, {}, {}});
    gen.n_pu = 0.4;
    for (int k = 0; k < seconds_psi * 8000; ++k) w.write({gen.next_si(base, t_ns), {}, {}, {}, {}});
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
