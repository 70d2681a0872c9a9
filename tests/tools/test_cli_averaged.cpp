// Averaged rotor-frame logs as a user meets them: written by `rpem sim --averaged-out` and by the independent
// generator's CLI (`indep_drive_log --averaged`), read by `rpem estimate`, which must recover the true ψm and
// R_s (1 %, 3 %) at 50, 200 and 1000 Hz, and by `rpem diagnose`, which must find an effect hidden in one;
// and the errors a bad log or an unusable configuration give.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

struct Estimates {
  double psi_m = 0, r_s = 0, r_s_at_standstill_end = 0;
  std::size_t rows = 0;
};

/// The estimate CSV's ψm at the end and R_s at t_rs (the end of the standstill).
Estimates read_estimates(const std::string& path, double t_rs) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("t,psi_m,r_s,", 0), 0U) << line;
  Estimates e;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    char comma = 0;
    double t = 0;
    s >> t >> comma >> e.psi_m >> comma >> e.r_s;
    if (t <= t_rs) e.r_s_at_standstill_end = e.r_s;
    ++e.rows;
  }
  return e;
}

std::string rpem() { return test::binary_dir() + "/tools/rpem"; }
std::string config() { return test::source_dir() + "/config/paper-ipmsm.yaml"; }

/// Every constant the diagnosis lists as identifiable has a cluster-robust 95 % interval within ±10 % of its
/// value (the identifiability rule, docs/diagnose.md), so positive.
void expect_identifiable_intervals_narrow(const nlohmann::json& d) {
  const nlohmann::json& c = d["calibration"];
  for (const auto& name : c["identifiable"]) {
    const std::string key = name.get<std::string>();
    const double v = c[key];
    ASSERT_TRUE(c[key + "_ci95"].is_array()) << key << "\n" << c.dump(2);
    const double lo = c[key + "_ci95"][0], hi = c[key + "_ci95"][1];
    EXPECT_GT(lo, 0.9 * v) << key << "\n" << c.dump(2);
    EXPECT_LT(hi, 1.1 * v) << key << "\n" << c.dump(2);
  }
}

class CliAveraged : public ::testing::TestWithParam<int> {};

TEST_P(CliAveraged, EstimateRecoversTheIndependentGeneratorsMachine) {
  // Standstill under load for 12 s, then 500 rpm; the true machine 5 % (ψm) and 15 % (R_s) off the file.
  test::TempFile profile("profile.csv"), avg("avg.csv"), truth("truth.json"), est("est.csv");
  std::ofstream(profile.path()) << "t_s,speed_rpm,torque_Nm\n0,0,16\n12,0,16\n12.5,500,16\n18,500,16\n";
  const std::string gen = test::binary_dir() + "/tests/independent_drive/indep_drive_log --config " + config() +
                          " --duration-s 18 --seed 9 --averaged --rate-Hz " + std::to_string(GetParam()) +
                          " --averaged-source drive --profile " + profile.path() +
                          " --set draw.psi_m_rel=-0.05 --set draw.r_s_rel=0.15 --out " + avg.path() + " --truth " +
                          truth.path();
  const test::ProcessResult g = test::run_command(gen);
  ASSERT_EQ(g.exit_code, 0) << gen << "\n" << g.output;
  const test::ProcessResult r =
      test::run_command(rpem() + " estimate --log " + avg.path() + " --config " + config() + " --out " + est.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("averaged samples"), std::string::npos) << r.output;
  const auto t = nlohmann::json::parse(std::ifstream(truth.path()))["true_machine"];
  const Estimates e = read_estimates(est.path(), 12.0);
  EXPECT_NEAR(e.psi_m / t["psi_m_Wb"].get<double>(), 1.0, 0.01) << r.output;
  EXPECT_NEAR(e.r_s_at_standstill_end / t["r_s_Ohm"].get<double>(), 1.0, 0.03) << r.output;
}

TEST_P(CliAveraged, EstimateRecoversOurSimulatorsMachine) {
  test::TempFile scenario("scenario.yaml"), avg("avg.csv"), est("est.csv");
  std::ofstream(scenario.path()) << "name: averaged-cli\nmachine: " << config() << "\nduration_s: 18\n"
                                 << "sensors: {current_noise_A: 0.02, current_lsb_A: 0.005, encoder_counts: 16384}\n"
                                 << "initial: {psi_m_Wb: 1.083, r_s_Ohm: 2.5875, speed_rpm: 0, torque_Nm: 16, u_dc_V: 565}\n"
                                 << "events:\n  - {t_s: 12, quantity: speed_rpm, kind: ramp, value: 500, duration_s: 0.5}\n";
  const test::ProcessResult s = test::run_command(rpem() + " sim --scenario " + scenario.path() + " --averaged-out " +
                                                  avg.path() + " --averaged-rate " + std::to_string(GetParam()));
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const test::ProcessResult r =
      test::run_command(rpem() + " estimate --log " + avg.path() + " --config " + config() + " --out " + est.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Estimates e = read_estimates(est.path(), 12.0);
  EXPECT_NEAR(e.psi_m / 1.083, 1.0, 0.01) << r.output;
  EXPECT_NEAR(e.r_s_at_standstill_end / 2.5875, 1.0, 0.03) << r.output;
  EXPECT_GT(e.rows, static_cast<std::size_t>(0.8 * 18 * GetParam()));
}

INSTANTIATE_TEST_SUITE_P(Rates, CliAveraged, ::testing::Values(50, 200, 1000),
                         [](const auto& p) { return std::to_string(p.param) + "Hz"; });

TEST(CliAveragedDiagnose, FindsAMagnetDriftHiddenInAnAveragedLog) {
  // The independent generator's VESC-like averages at 200 Hz of a machine whose ψm follows the magnet
  // temperature (−0.1 %/K, 25 → 65 °C); the configuration is the true machine at 25 °C otherwise.
  test::TempFile avg("avg.csv"), truth("truth.json");
  const std::string dir = avg.path() + ".diag";
  const std::string gen = test::binary_dir() + "/tests/independent_drive/indep_drive_log --config " + config() +
                          " --effects psim_drift --nominal --seed 4 --duration-s 30 --averaged --rate-Hz 200"
                          " --averaged-source drive --out " +
                          avg.path() + " --truth " + truth.path();
  const test::ProcessResult g = test::run_command(gen);
  ASSERT_EQ(g.exit_code, 0) << gen << "\n" << g.output;
  const test::ProcessResult r = test::run_command(rpem() + " diagnose --log " + avg.path() + " --config " + config() +
                                                  " --reference-temperature-C 25 --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto d = nlohmann::json::parse(std::ifstream(dir + "/diagnosis.json"));
  EXPECT_EQ(d["log"]["model"], "steady_state");
  EXPECT_EQ(d["log"]["kind"], "averaged");
  ASSERT_GE(d["effects"].size(), 1U) << d["effects"].dump(2);
  EXPECT_EQ(d["effects"][0]["name"], "psim_drift") << d["effects"].dump(2);
  // ±20 % of the hidden coefficient: the steady-state replay leaves the windows around steps out.
  const double coeff = d["effects"][0]["params"]["coeff_per_K"];
  EXPECT_LT(coeff, -0.0008);
  EXPECT_GT(coeff, -0.0012);
  // The gain is over the calibrated baseline (issue 10), which already takes the mean ψm error (0.35 →
  // 0.14 A held out on this log); what is left is the drift's own part.
  EXPECT_GT(d["effects"][0]["gain_pct"].get<double>(), 10.0);
  EXPECT_LT(d["calibration"]["heldout_rms"].get<double>(), 0.5 * d["baseline"]["heldout_rms"].get<double>());
  // Nothing else: an L_d curve that trades against the calibrated L_d (10 % held-out gain on these rows) is
  // not named, and L_d is listed identifiable only with a narrow interval.
  EXPECT_EQ(d["effects"].size(), 1U) << d["effects"].dump(2);
  expect_identifiable_intervals_narrow(d);

  // The transient replay needs phase samples: refused, naming the log.
  const test::ProcessResult t = test::run_command(rpem() + " diagnose --log " + avg.path() + " --config " + config() +
                                                  " --model transient --out " + dir);
  EXPECT_EQ(t.exit_code, 65) << t.output;
  EXPECT_NE(t.output.find("replays only the steady-state model"), std::string::npos) << t.output;
  std::filesystem::remove_all(dir);
}

TEST(CliAveragedDiagnose, NamesNothingInAnAveragedLogOfAMachineOffItsConfiguration) {
  // Nulls: the independent generator's machine drawn off the configuration (ψm ±8 %, R_s ±25 %, L ±5 %),
  // nothing hidden, VESC-like averages over uneven windows (jitter 0.3) at 1 kHz, where a window more often
  // spans a transient: the averaging's own model error must not be named as an effect (issue 10), and the
  // calibration takes ψm within 2 %. There L_d is not identified (no field weakening: ω·L_d·i_d carries
  // almost nothing), so an L_d curve, which only that product carries, is not identified either
  // (docs/diagnose.md, "An effect that shapes a constant").
  for (int seed : {5, 12}) {
    test::TempFile avg("avg.csv"), truth("truth.json");
    const std::string dir = avg.path() + ".diag";
    const std::string gen = test::binary_dir() + "/tests/independent_drive/indep_drive_log --config " + config() +
                            " --effects none --seed " + std::to_string(seed) +
                            " --duration-s 30 --averaged --rate-Hz 1000 --averaged-source drive --out " + avg.path() +
                            " --truth " + truth.path();
    const test::ProcessResult g = test::run_command(gen);
    ASSERT_EQ(g.exit_code, 0) << gen << "\n" << g.output;
    const test::ProcessResult r =
        test::run_command(rpem() + " diagnose --log " + avg.path() + " --config " + config() + " --out " + dir);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto d = nlohmann::json::parse(std::ifstream(dir + "/diagnosis.json"));
    const auto t = nlohmann::json::parse(std::ifstream(truth.path()));
    EXPECT_EQ(d["effects"].size(), 0U) << "seed " << seed << "\n" << d["effects"].dump(2);
    expect_identifiable_intervals_narrow(d);
    EXPECT_NEAR(d["calibration"]["psi_m_Wb"].get<double>() / t["true_machine"]["psi_m_Wb"].get<double>(), 1.0, 0.02) << seed;
    std::filesystem::remove_all(dir);
  }
}

/// The final ψm of `rpem estimate`'s summary ("psi_m = X Wb"), as printed; "" where none.
std::string final_psi_m(const std::string& output) {
  const std::size_t at = output.find("psi_m = ");
  return at == std::string::npos ? "" : output.substr(at + 8, output.find(' ', at + 8) - at - 8);
}

TEST(CliAveragedEstimate, ALogThatEndsInsideABridgeReleaseEndsWithoutThatWindow) {
  // docs/derivations.md §13, "A chain's last window": 90 ms windows of config/vesc-6374-outrunner.yaml's machine with
  // ψm 15 % low at 1500 rad/s and 5 A, from its steady-state equations, printed to two decimals; the bridge released
  // half-way through the 21st, zeros reported while off. Cut there, nothing shows the release: the log's end ends the chain, and the
  // final estimate is the one a log going on to show the release (two off windows) ends with, to the digit. (It
  // ended 2.30 mWb against 3.00 on a user's ride cut so.)
  const double r = 0.025, l = 20e-6, psi = 0.85 * 0.004633, omega = 1500.0, i_q = 5.0, h = 0.09;
  const double u_d = -omega * l * i_q, u_q = r * i_q + omega * psi;
  auto log_of = [&](int windows) {
    std::string text = "t,t_start,i_d,i_q,u_d,u_q,omega_el\n";
    for (int j = 0; j < windows; ++j) {
      const double share = j < 20 ? 1.0 : (j == 20 ? 0.5 : 0.0);
      char row[160];
      std::snprintf(row, sizeof row, "%.17g,%.17g,0,%.2f,%.2f,%.2f,%.17g\n", (j + 1) * h, j * h, share * i_q, share * u_d,
                    share * u_q, omega);
      text += row;
    }
    return text;
  };
  // A logger printing two decimals (10 mV, 10 mA), as the configuration says.
  std::string yaml = test::read_file(test::source_dir() + "/config/vesc-6374-outrunner.yaml");
  const std::string frame = "    angle_source: sensorless\n";
  ASSERT_NE(yaml.find(frame), std::string::npos);
  yaml.replace(yaml.find(frame), frame.size(), frame + "    voltage_resolution_V: 0.01\n    current_resolution_A: 0.01\n");
  test::TempFile config_file("outrunner-2-decimals.yaml", yaml), cut("cut.csv", log_of(21)), shown("shown.csv", log_of(23)),
      est("est.csv");
  const std::string outrunner = config_file.path();
  const test::ProcessResult a =
      test::run_command(rpem() + " estimate --log " + cut.path() + " --config " + outrunner + " --out " + est.path());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const std::string written = test::read_file(est.path());
  const std::string last_row = written.substr(written.rfind('\n', written.size() - 2) + 1);
  const test::ProcessResult b =
      test::run_command(rpem() + " estimate --log " + shown.path() + " --config " + outrunner + " --out " + est.path());
  ASSERT_EQ(b.exit_code, 0) << b.output;
  ASSERT_NE(final_psi_m(a.output), "") << a.output;
  EXPECT_EQ(final_psi_m(a.output), final_psi_m(b.output)) << a.output << b.output;
  EXPECT_NEAR(std::stod(final_psi_m(a.output)) / psi, 1.0, 0.01) << a.output;
  // The mixed window's own row, written as it arrived, reads about half the flux's worth lower.
  EXPECT_LT(std::stod(last_row.substr(last_row.find(',') + 1)), 0.9 * psi) << last_row;
  EXPECT_NE(a.output.find("1 window ending a chain (before a gap or at the log's end) left out of the estimates"),
            std::string::npos)
      << a.output;
  EXPECT_EQ(b.output.find("ending a chain"), std::string::npos) << b.output;  // judged: retracted as mixed
}

TEST(CliAveragedErrors, ABadLogNamesFileLineAndColumn) {
  test::TempFile avg("bad.csv"), est("est.csv");
  std::ofstream(avg.path()) << "t,t_start,i_d,i_q,u_d,u_q,omega_el\n0.005,0,0,1,0,10,100\n0.004,0.005,0,1,0,10,100\n";
  const test::ProcessResult r =
      test::run_command(rpem() + " estimate --log " + avg.path() + " --config " + config() + " --out " + est.path());
  EXPECT_EQ(r.exit_code, 65) << r.output;
  EXPECT_NE(r.output.find(avg.path() + ":3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("column t"), std::string::npos) << r.output;
  std::ofstream(avg.path()) << "t,t_start,i_d,i_q,u_d,u_q\n0.005,0,0,1,0,10\n";
  const test::ProcessResult missing =
      test::run_command(rpem() + " estimate --log " + avg.path() + " --config " + config() + " --out " + est.path());
  EXPECT_EQ(missing.exit_code, 65) << missing.output;
  EXPECT_NE(missing.output.find("omega_el"), std::string::npos) << missing.output;
}

TEST(CliAveragedErrors, PerPhaseCorrectionsAreRefusedForAveragedSamples) {
  test::TempFile avg("avg.csv"), cfg("cfg.yaml"), est("est.csv");
  std::ofstream(avg.path()) << "t,t_start,i_d,i_q,u_d,u_q,omega_el\n0.005,0,0,1,0,10,100\n";
  std::ifstream in(config());
  std::stringstream text;
  text << in.rdbuf() << "model_extensions:\n  current_offset: [{phase: a, offset_A: 0.05}]\n";
  std::ofstream(cfg.path()) << text.str();
  const test::ProcessResult r =
      test::run_command(rpem() + " estimate --log " + avg.path() + " --config " + cfg.path() + " --out " + est.path());
  EXPECT_EQ(r.exit_code, 78) << r.output;
  EXPECT_NE(r.output.find("rotor-frame mean"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rpem
