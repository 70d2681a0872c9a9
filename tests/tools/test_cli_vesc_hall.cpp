// A VESC in Hall mode, as VESC Tool logs it (scenarios/vesc-tool-hall.yaml: our emulator's Hall sensors read as
// the firmware reads them, docs/scenarios.md "Hall sensors"), read by `rpem estimate` with the outrunner's file
// saying where its frame comes from. GIVEN the ride, whose frame is up to 30° off the rotor's at crawling speed
// WHEN it is estimated with `angle_source: hall` THEN ψm ends within 2 % and R_s within 5 % of the truth (issue 23's
// accuracies), and R_s adapts on more reads than a sensorless frame lets it and on no more than a sensor's would:
// the Hall bound (docs/derivations.md §13, "Hall sensors") lies between the two.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

constexpr double kPsiTrueWb = 0.0037064, kRsTrueOhm = 0.03125;  // the scenario's plant, constant

std::string rpem() { return test::binary_dir() + "/tools/rpem"; }

/// The 0-based index of the column `name` in a CSV header (0 also where it is missing: none is at 0 here).
std::size_t column_of(const std::string& header, const std::string& name) {
  std::stringstream cells(header);
  std::string cell;
  for (std::size_t c = 0; std::getline(cells, cell, ','); ++c) {
    if (cell == name) return c;
  }
  return 0;
}

struct Estimated {
  double psi_m_Wb = NAN, r_s_Ohm = NAN;
  long excites_r_s = -1;  ///< the reads that excited R_s (alone or with ψm)
  std::string output;
};

/// rpem estimate on `log` with `config` (in config/), its angle source replaced by `source`; `estimates` keeps the CSV;
/// `options` more of rpem estimate's.
Estimated estimate(const std::string& log, const std::string& source, const std::string& config = "vesc-6374-outrunner.yaml",
                   const std::string& estimates = "", const std::string& options = "") {
  std::ifstream in(test::source_dir() + "/config/" + config);
  std::stringstream text;
  text << in.rdbuf();
  const std::string edited =
      std::regex_replace(text.str(), std::regex("angle_source: sensorless"), "angle_source: " + source);
  EXPECT_TRUE(source == "sensorless" || edited != text.str());
  const test::TempFile cfg("hall_" + std::to_string(std::hash<std::string>{}(source)) + ".yaml", edited),
      out("hall_estimates.csv");
  Estimated run;
  const std::string csv = estimates.empty() ? out.path() : estimates;
  const test::ProcessResult r =
      test::run_command(rpem() + " estimate --log " + log + " --config " + cfg.path() + " --out " + csv + options);
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
  const std::size_t column = column_of(line, "frame_error");
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
  const bool declared = hall.output.find("r_s not identifiable") != std::string::npos;
  if (!declared) {
    EXPECT_NEAR(hall.r_s_Ohm / kRsTrueOhm, 1.0, 0.05) << hall.output;
  }
  const Estimated sensorless = estimate(log.path(), "sensorless"), sensor = estimate(log.path(), "sensor");
  EXPECT_GT(hall.excites_r_s, sensorless.excites_r_s) << hall.output << sensorless.output;
  EXPECT_LE(hall.excites_r_s, sensor.excites_r_s) << hall.output << sensor.output;
}

// The independent generator's Hall ride (tests/independent_vesc, README "Hall mode": the firmware's foc_correct_hall
// re-expressed from its source, a detected table, the observer above foc_sl_erpm; a power stage with dead time),
// read as the firmware reports it (config/vesc-6374-firmware.yaml). ψm within 2 %; R_s adapts between a sensorless
// frame's reads and a sensor's, and only on reads whose frame the generator's own bound holds (half a state, the
// table's 2.3°, one cycle's turn: 0.566 rad at most on its crawl; its truth, never an estimator, says what each
// read's frame was). With `hall`, R_s as read ends within issue 23's 5 %: below foc_hall_interp_erpm each window's
// speed is the tachometer's over it and its neighbours, not the firmware's PLL speed at the read, which at a crawl
// (2–40 rad/s) reads about half the read's mean and left R_s +9.6 % high (docs/derivations.md §13, "The count's speed
// at a crawl"). The other two sources take the PLL's speed everywhere (+6.3 % sensorless, +16.6 % with a sensor: a
// Hall drive configured as what it is not); with the read's mean speed from the generator's truth in the erpm column,
// read as it stands (no PLL rebuild), R_s ends within 5 % in every mode and ψm within 2 % — the estimator and the
// regimes are right given the speed.
TEST(CliVescHall, TheIndependentGeneratorsHallRideAdaptsRsOnlyWhereItsSensorsBoundTheFrame) {
  const test::TempFile log("indep_hall.csv"), truth("indep_hall.json"), estimates("indep_hall_estimates.csv");
  const test::ProcessResult gen = test::run_command(
      test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + test::source_dir() +
      "/config/vesc-6374-outrunner.yaml --hall --seed 4 --duration-s 70 --psi-m-rel 0.2 --r-s-rel -0.15 --out " +
      log.path() + " --truth " + truth.path());
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth.path()));
  const double psi_true = t.at("true_at_end").at("psi_m_Wb").get<double>();

  const Estimated hall = estimate(log.path(), "hall", "vesc-6374-firmware.yaml", estimates.path());
  EXPECT_NEAR(hall.psi_m_Wb / psi_true, 1.0, 0.02) << hall.output;
  EXPECT_NEAR(hall.r_s_Ohm / t.at("true_at_end").at("r_s_Ohm").get<double>(), 1.0, 0.05) << hall.output;
  EXPECT_EQ(hall.output.find("r_s not identifiable"), std::string::npos) << hall.output;
  const Estimated sensorless = estimate(log.path(), "sensorless", "vesc-6374-firmware.yaml");
  const Estimated sensor = estimate(log.path(), "sensor", "vesc-6374-firmware.yaml");
  EXPECT_GT(hall.excites_r_s, sensorless.excites_r_s) << hall.output << sensorless.output;
  EXPECT_LE(hall.excites_r_s, sensor.excites_r_s) << hall.output << sensor.output;

  // Row by row: the estimate CSV's k-th row is the log's (k+1)-th (the first row opens the first window).
  std::ifstream in(estimates.path());
  std::string line;
  std::getline(in, line);
  const std::size_t regime_column = column_of(line, "regime");
  ASSERT_GT(regime_column, 0U) << line;
  const nlohmann::json& rows = t.at("rows");
  std::size_t k = 1, adapted = 0;
  double worst = 0.0;
  while (std::getline(in, line) && k < rows.size()) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t c = 0; c <= regime_column; ++c) std::getline(row, cell, ',');
    const int regime = std::stoi(cell);
    if (regime == 0 || regime == 2) {  // excites both, excites R_s
      ++adapted;
      worst = std::max(worst, std::abs(rows[k].at("frame_error_mean_rad").get<double>()));
    }
    ++k;
  }
  EXPECT_EQ(static_cast<long>(adapted), hall.excites_r_s);
  EXPECT_LE(worst, 0.566) << adapted << " reads";

  // The same log with each read's erpm the truth's mean electrical speed over its window, and VESC Tool's map
  // without `pll` (the column is then the window's mean, docs/drive-log.md "The speed is the PLL's at the read").
  std::ifstream log_in(log.path());
  std::string header;
  std::getline(log_in, header);
  const std::size_t erpm_column = column_of(std::regex_replace(header, std::regex(";"), ","), "erpm");
  ASSERT_GT(erpm_column, 0U) << header;
  std::ostringstream true_speed;
  true_speed << header << '\n';
  std::size_t line_number = 1;
  for (const nlohmann::json& row : rows) {
    std::string data;
    ASSERT_TRUE(std::getline(log_in, data));
    ++line_number;
    ASSERT_EQ(row.at("line").get<std::size_t>(), line_number);
    std::stringstream cells(data);
    std::string cell, edited;
    for (std::size_t c = 0; std::getline(cells, cell, ';'); ++c) {
      if (c == erpm_column) cell = std::to_string(row.at("omega_el_mean_rad_s").get<double>() * 30.0 / M_PI);
      edited += (c == 0 ? "" : ";") + cell;
    }
    true_speed << edited << '\n';
  }
  std::ifstream map_in(test::source_dir() + "/config/log-maps/vesc-tool.yaml");
  std::stringstream map_text;
  map_text << map_in.rdbuf();
  const std::string no_pll = std::regex_replace(map_text.str(), std::regex(", pll: \\{kp: 2000, ki: 30000\\}"), "");
  ASSERT_NE(no_pll, map_text.str());
  const test::TempFile speed_log("indep_hall_true_speed.csv", true_speed.str()), map("vesc_tool_no_pll.yaml", no_pll);
  for (const char* source : {"hall", "sensorless", "sensor"}) {
    const Estimated run = estimate(speed_log.path(), source, "vesc-6374-firmware.yaml", "", " --log-map " + map.path());
    EXPECT_NEAR(run.psi_m_Wb / psi_true, 1.0, 0.02) << source << run.output;
    EXPECT_NEAR(run.r_s_Ohm / t.at("true_at_end").at("r_s_Ohm").get<double>(), 1.0, 0.05) << source << run.output;
  }
}

}  // namespace
}  // namespace rpem

namespace rpem {
namespace {

/// The speed each window of an estimate CSV stood for [rad/s] (n_pu times the base, the base from the reads above
/// 500 rad/s, where every speed is the PLL's rebuilt one and within a fraction of a percent of the truth's mean).
std::vector<double> speeds_used(const std::string& csv, const nlohmann::json& rows) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  const std::size_t n_column = column_of(line, "n_pu");
  std::vector<double> n_pu;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t c = 0; c <= n_column; ++c) std::getline(row, cell, ',');
    n_pu.push_back(std::stod(cell));
  }
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < n_pu.size() && k + 1 < rows.size(); ++k) {
    const double w = rows[k + 1].at("omega_el_mean_rad_s").get<double>();
    if (std::abs(w) > 500.0) {
      num += n_pu[k] * w;
      den += n_pu[k] * n_pu[k];
    }
  }
  for (double& n : n_pu) n *= num / den;
  return n_pu;
}

// rpemd's poll rate (200 Hz reads: the independent generator's Hall ride with VESC Tool's link replaced by a CAN
// poller's: no loss, no stall — tests/independent_vesc): a 5 ms window holds no step of the tachometer or one, so the three-read run
// alone would count 0 or ±70 rad/s; the run grown while its sides agree (docs/derivations.md §13, "The count's speed
// over a grown run" — what rpemd's VESC source counts too, daemon/count_delay.hpp) puts each crawling window's
// speed within the count's bound over a full run (2 steps over 0.5 s: 4.2 rad/s) of the truth's mean in RMS, where
// the PLL's rebuilt speed is off by several times that; ψm ends within 2 % and R_s within 5 %.
TEST(CliVescHall, AtRpemdsPollRateEachCrawlingWindowsSpeedIsCountedOverAGrownRun) {
  const test::TempFile log("indep_hall_200.csv"), truth("indep_hall_200.json");
  const test::TempFile counted("hall_200_counted.csv"), pll("hall_200_pll.csv");
  const test::ProcessResult gen =
      test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + test::source_dir() +
                        "/config/vesc-6374-outrunner.yaml --hall --seed 4 --duration-s 70 --psi-m-rel 0.2 --r-s-rel -0.15 "
                        "--poll-rate-Hz 200 --rate-Hz 180 --set poller.rtt_min_s=0.0005 --set poller.rtt_sigma_log=0.05 "
                        "--set poller.loss_probability=0 --set poller.stall_probability=0 --out " +
                        log.path() + " --truth " + truth.path());
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth.path()));
  const nlohmann::json& rows = t.at("rows");
  ASSERT_GT(rows.size(), 13'000U);

  const Estimated hall = estimate(log.path(), "hall", "vesc-6374-firmware.yaml", counted.path());
  EXPECT_NEAR(hall.psi_m_Wb / t.at("true_at_end").at("psi_m_Wb").get<double>(), 1.0, 0.02) << hall.output;
  // R_s identified, not declared: the crawl's reads carry an inverter's d-axis voltage error no parameter explains
  // but none moves either; judged on the per-row error they were skipped as outliers (31 % of the reads) and R_s
  // adapted on too few to be identified (docs/derivations.md §14).
  EXPECT_EQ(hall.output.find("r_s not identifiable"), std::string::npos) << hall.output;
  EXPECT_NEAR(hall.r_s_Ohm / t.at("true_at_end").at("r_s_Ohm").get<double>(), 1.0, 0.05) << hall.output;
  // The same with the count never taken: the PLL's rebuilt speed everywhere (rpemd before it counted).
  (void)estimate(log.path(), "hall\n    hall_interpolation_speed_rad_s: 0", "vesc-6374-firmware.yaml", pll.path());

  const std::vector<double> with_count = speeds_used(counted.path(), rows), with_pll = speeds_used(pll.path(), rows);
  ASSERT_EQ(with_count.size(), with_pll.size());
  double count_sq = 0.0, pll_sq = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < with_count.size() && k + 1 < rows.size(); ++k) {
    const nlohmann::json& r = rows[k + 1];
    const double w = r.at("omega_el_mean_rad_s").get<double>();
    if (std::abs(w) >= 52.0 || r.at("bridge").get<std::string>() != "modulating" ||
        std::abs(r.at("i_q_mean_A").get<double>()) <= 3.0) {
      continue;
    }
    count_sq += std::pow(with_count[k] - w, 2);
    pll_sq += std::pow(with_pll[k] - w, 2);
    ++n;
  }
  ASSERT_GT(n, 3000);
  const double count_rms = std::sqrt(count_sq / n), pll_rms = std::sqrt(pll_sq / n);
  std::printf("[ crawl    ] %d windows: counted RMS %.2f rad/s, the PLL's %.2f rad/s\n", n, count_rms, pll_rms);
  EXPECT_LT(count_rms, 2.0 * (M_PI / 3.0) / 0.5);
  EXPECT_GT(pll_rms, 3.0 * count_rms);
}

// The same ride over VESC Tool's own link at 200 Hz (seed 5: requests and replies lost, replies stalled, as the
// generator draws them from VESC Tool's polling): one reply, lost while the rotor coasted at −620 rad/s, reset the
// firmware's means 0.37 s into a 1.0 s gap, so the next row's window was a third of what its stamps say, and its
// rebuilt speed 62 rad/s (13 %) off the truth's mean moved ψm by −7 % (it ended −6.9 %). Each row 0.99 s or more after
// the one before (VESC Tool asked again), the row after it, and the windows around a stale reply have unknown windows
// and are not used (docs/drive-log.md, "Rows stamped late").
TEST(CliVescHall, OverVescToolsLinkAtItsFastestTheWindowsAroundALateReadAreNotUsed) {
  const test::TempFile log("indep_hall_200_link.csv"), truth("indep_hall_200_link.json");
  const test::ProcessResult gen =
      test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + test::source_dir() +
                        "/config/vesc-6374-outrunner.yaml --hall --seed 5 --duration-s 70 --poll-rate-Hz 200 --rate-Hz 180 "
                        "--set poller.rtt_min_s=0.0005 --set poller.rtt_sigma_log=0.05 --out " +
                        log.path() + " --truth " + truth.path());
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth.path()));
  ASSERT_GT(t.at("reads").at("lost_replies").get<int>(), 0);
  const Estimated hall = estimate(log.path(), "hall", "vesc-6374-firmware.yaml");
  EXPECT_NE(hall.output.find("windows unknown, not used"), std::string::npos) << hall.output;
  EXPECT_NEAR(hall.psi_m_Wb / t.at("true_at_end").at("psi_m_Wb").get<double>(), 1.0, 0.02) << hall.output;
  // R_s identified, not declared (as at rpemd's poll rate above).
  EXPECT_EQ(hall.output.find("r_s not identifiable"), std::string::npos) << hall.output;
  EXPECT_NEAR(hall.r_s_Ohm / t.at("true_at_end").at("r_s_Ohm").get<double>(), 1.0, 0.05) << hall.output;
}

}  // namespace
}  // namespace rpem
