// `rpem estimate` as a user runs it: a drive log written by this test from the model (standstill
// under load, then 0.4 pu), with the machine's ψm 8 % and R_s 6 % below the configured values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "rpem/io/drive_log.hpp"
#include "rpem/io/machine_config.hpp"
#include "support/data_file.hpp"
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
    for (int k = 0; k < seconds_rs * 8000; ++k) w.write({gen.next_si(base, t_ns), {}, {}});
    gen.n_pu = 0.4;
    for (int k = 0; k < seconds_psi * 8000; ++k) w.write({gen.next_si(base, t_ns), {}, {}});
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
      w.write({gen.next_si(base, t_ns), {}, {}});
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

/// An estimate CSV's columns by name.
struct EstimateTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  [[nodiscard]] std::size_t column(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    return static_cast<std::size_t>(it - names.begin());
  }
};

EstimateTable read_table(const std::string& path) {
  std::ifstream in(path);
  std::string line, cell;
  EstimateTable t;
  std::getline(in, line);
  for (std::stringstream h(line); std::getline(h, cell, ',');) t.names.push_back(cell);
  while (std::getline(in, line)) {
    std::vector<double> row;
    for (std::stringstream r(line); std::getline(r, cell, ',');) row.push_back(std::stod(cell));
    t.rows.push_back(row);
  }
  return t;
}

/// What each row of the Paderborn profile says of ψm with the configuration's R_s and L_d, from its steady-state
/// q row, ψ_row = (u_q − R·i_q − ω·L_d·i_d)/ω (NaN below 200 rad/s), read from the phase log `log`.
std::vector<double> paderborn_row_psi_m(const std::string& log) {
  const core::MachineSi m = io::load_machine_config(test::source_dir() + "/config/paderborn-pmsm.yaml").machine;
  io::DriveLogReader reader(log);
  io::DriveLogRow row;
  std::vector<double> per_row;
  while (reader.next(row)) {
    const core::DriveSample& s = row.sample;
    per_row.push_back(std::abs(s.omega_el_rad_s) > 200.0
                          ? (s.u_V[1] - m.r_s_Ohm * s.i_A[1] - s.omega_el_rad_s * m.l_d_H * s.i_A[0]) / s.omega_el_rad_s
                          : std::nan(""));
  }
  return per_row;
}

/// The Paderborn profile converted by scripts/paderborn_to_drive_log.py (extra options `options`) to `out`.
void convert_paderborn(const std::string& out, const std::string& options) {
  const std::string source = test::data_file("paderborn-motor-temperature/profile_A_every5th.csv");
  const auto r = test::run_command("python3 " + test::source_dir() + "/scripts/paderborn_to_drive_log.py " + source + " " +
                                   out + " --pole-pairs 4 --sample-period-s 2.5" + options);
  ASSERT_EQ(r.exit_code, 0) << r.output;
}

TEST(CliEstimate, PaderbornRowsSecondsApartAdaptPsiMAsSteadyStateObservations) {
  // The Paderborn bench profile (2.5 s between rows; docs/diagnose.md): before issue 23 every row
  // resynchronised and ψm never moved from its start. Each row is a steady-state observation now. Checked
  // against what each row says with the configuration's R_s and L_d (paderborn_row_psi_m): the estimate
  // follows the magnet (ψm falls as it heats) and ends within 1 % of the last rows' median.
  test::TempFile log("paderborn.csv"), est("paderborn-est.csv");
  convert_paderborn(log.path(), "");
  const auto r = test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " +
                                   test::source_dir() + "/config/paderborn-pmsm.yaml --out " + est.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rpem estimate: regimes: excites_both "), std::string::npos) << r.output;

  const EstimateTable t = read_table(est.path());
  const std::size_t psi = t.column("psi_m"), code = t.column("code"), regime = t.column("regime");
  std::size_t adapted = 0, excluded = 0;
  for (const auto& row : t.rows) {
    adapted += row[code] == 0.0 ? 1 : 0;
    excluded += row[regime] >= 4.0 ? 1 : 0;
  }
  EXPECT_GT(adapted, 2900U) << r.output;  // of 3003 rows
  EXPECT_LT(excluded, 30U) << r.output;

  const core::MachineSi m = io::load_machine_config(test::source_dir() + "/config/paderborn-pmsm.yaml").machine;
  const std::vector<double> per_row = paderborn_row_psi_m(log.path());
  ASSERT_EQ(per_row.size(), t.rows.size());
  std::vector<double> tail;
  for (std::size_t k = per_row.size() - 100; k < per_row.size(); ++k) {
    if (std::isfinite(per_row[k])) tail.push_back(per_row[k]);
  }
  std::nth_element(tail.begin(), tail.begin() + tail.size() / 2, tail.end());
  const double end_median = tail[tail.size() / 2];
  EXPECT_NEAR(t.rows.back()[psi] / end_median, 1.0, 0.01) << "psi_m " << t.rows.back()[psi] << " rows " << end_median;
  EXPECT_GT(std::abs(t.rows.back()[psi] / m.psi_m_Wb - 1.0), 0.005);  // it moved from the configured start
}

TEST(CliEstimate, PaderbornAveragedRowsFollowEachRowsPsiMFromTheFirstRowsAtSpeed) {
  // The same profile as an averaged log (t_start = t: each row an instantaneous sample, standalone at 2.5 s;
  // docs/derivations.md §13), as issue 24's thermal validation runs it. Each adapted row's gain is
  // 1 − e^{−λ·2.5 s} = 0.9985 (λ = γ_L/T_samp = 2.6/s for ψm), so ψ̂m is the row's own steady-state solution
  // (paderborn_row_psi_m, from the phase log of the same rows) up to 0.15 % of the previous row's error and the
  // d row's share of the least squares: within 0.5 % (≈ 4 K of magnet temperature at NdFeB's −0.12 %/K) from
  // 20 s on, four rows after the speed reaches 5 000 rpm, to the end. This is what the thermal fit anchors the
  // magnet law on (the first magnet observations). The regression it guards against (docs/thermal.md, "Since
  // the regimes merge"): the rows as one chain, whose second differences over the run-up were taken for
  // noise, held ψ̂m at its start, 10 % off, until 80 s, and moved the validation's magnet by −8.6 K.
  test::TempFile phase("paderborn-phase.csv"), log("paderborn-averaged.csv"), est("paderborn-averaged-est.csv");
  convert_paderborn(phase.path(), "");
  convert_paderborn(log.path(), " --averaged");
  const auto r = test::run_command(test::binary_dir() + "/tools/rpem estimate --log " + log.path() + " --config " +
                                   test::source_dir() + "/config/paderborn-pmsm.yaml --out " + est.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("averaged samples"), std::string::npos) << r.output;

  const EstimateTable t = read_table(est.path());
  const std::vector<double> per_row = paderborn_row_psi_m(phase.path());
  ASSERT_EQ(per_row.size(), t.rows.size());
  const std::size_t time = t.column("t"), psi = t.column("psi_m");
  std::size_t judged = 0;
  double worst = 0.0, worst_t = 0.0;
  for (std::size_t k = 0; k < t.rows.size(); ++k) {
    if (t.rows[k][time] < 20.0 || !std::isfinite(per_row[k])) continue;
    ++judged;
    const double deviation = std::abs(t.rows[k][psi] / per_row[k] - 1.0);
    if (deviation > worst) {
      worst = deviation;
      worst_t = t.rows[k][time];
    }
  }
  EXPECT_GT(judged, 2950U);  // of 3003 rows
  EXPECT_LE(worst, 0.005) << "psi_m off its row's steady-state value by " << worst << " at t = " << worst_t << " s";
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
