// Issue 23 item 6, the `rpem estimate` half: VESC Tool logs shaped like the field's — every regime of a real
// drive, the machine off its configuration — written by two generators, read as a user reads them, must end
// within 2 % on ψm and 5 % on R_s of the truth the generator states (or say R_s is not identifiable, and why):
//   - our emulator (`rpem sim --vesc-tool-out`, scenarios/vesc-tool-field.yaml), which reports the period's
//     mean voltage, with config/vesc-6374-outrunner.yaml;
//   - the independent generator (tests/independent_vesc, written from the firmware's sources apart from
//     ours), which reports the firmware's command, with config/vesc-6374-firmware.yaml (the same machine and
//     estimator; the firmware's report: docs/derivations.md §11, "Reported command").
// The truth comes from the generators (their truth files), never from an estimator. ~1–2 min: label slow.
//
// Measured 2026-12-06 (build/dev; each case prints its figures), the last estimate against the truth:
//   - the ride: ψm +0.19 %, R_s −20.0 % (its configured start: no window of the sensorless ride excites it),
//     declared not identifiable (±75 %). Before the mixed-window rule (docs/derivations.md §13, "Mixed windows") it
//     ended at ψm −21 %: windows in which the bridge is released or takes over (part modulating, part off, zeros
//     reported while off) read ψm at the modulating share.
//   - seed 1: ψm −0.02 %, R_s +1.87 % (R_s required within 5 % although its start still decides ±8 %).
//   - seed 2 (zeros while off, across midnight): ψm −1.18 %, R_s −0.83 %. It ended at ψm −2.01 % while `erpm`
//     was taken for the window's mean speed: it is the firmware's PLL speed at the read, lagging the rotor by
//     k_p/k_i = 66.7 ms in a ramp, and ψ̂m drifted ~2 % low in the last zero-current coast-down (515–520 s),
//     where a decelerating rotor reads fast. The reader now rebuilds each window's mean speed from the PLL's
//     speeds at its two reads (docs/derivations.md §13, "Speed at the read").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

std::string rpem() { return test::binary_dir() + "/tools/rpem"; }
std::string indep_vesc_log() { return test::binary_dir() + "/tests/independent_vesc/indep_vesc_log"; }
std::string config(const char* name) { return test::source_dir() + "/config/" + name; }

struct Truth {
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0;
};

struct Final {
  double psi_m_Wb = NAN, r_s_Ohm = NAN;
  std::string output;  ///< rpem estimate's stdout and stderr
};

/// rpem estimate on the log (with `options`); the last estimate row.
Final estimate(const std::string& log, const std::string& cfg, const std::string& options = "") {
  test::TempFile out("estimates.csv");
  Final f;
  const auto r =
      test::run_command(rpem() + " estimate --log " + log + " --config " + cfg + " --out " + out.path() + " " + options);
  f.output = r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(out.path());
  std::string line, last;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("t,psi_m,r_s,", 0), 0U) << line;
  while (std::getline(in, line)) last = line;
  std::stringstream s(last);
  double t = 0;
  char comma = 0;
  s >> t >> comma >> f.psi_m_Wb >> comma >> f.r_s_Ohm;
  return f;
}

/// Within 2 % on ψm; within 5 % on R_s, or R_s declared not identifiable with a reason (unless `r_s_required`:
/// a log that met 5 % keeps meeting it, declared or not).
void expect_field_accuracy(const Final& f, const Truth& truth, const std::string& what, bool r_s_required = false) {
  EXPECT_NEAR(f.psi_m_Wb / truth.psi_m_Wb, 1.0, 0.02) << what << "\n" << f.output;
  const bool declared = f.output.find("r_s not identifiable") != std::string::npos;
  if (declared) {  // with a reason: its start, or voltages rebuilt from a magnitude that no lock test can judge
    EXPECT_TRUE(f.output.find("its start still decides") != std::string::npos ||
                f.output.find("the angle-lock test cannot exclude a sensorless drive's open-loop start-ups") !=
                    std::string::npos)
        << f.output;
    // It says how often R_s adapted against how often a window excited it (the regimes line's excites_both +
    // excites_r_s), and names the gain schedule's key that keeps an excited window from adapting.
    std::smatch regimes, clause;
    if (f.output.find("its start still decides") != std::string::npos) {
      const bool counted = std::regex_search(
          f.output, regimes, std::regex("regimes: excites_both ([0-9]+), excites_psi_m [0-9]+, excites_r_s ([0-9]+)"));
      const bool said = std::regex_search(
          f.output, clause,
          std::regex("r_s not identifiable[^\n]*it adapted on ([0-9]+) of the ([0-9]+) samples that excite it; the "
                     "others: outside the gain schedule \\(r_s adapts only below "
                     "estimator.scheduler.r_s_max_speed_rpm, [0-9.]+ rpm\\)"));
      EXPECT_TRUE(counted) << f.output;
      EXPECT_TRUE(said) << f.output;
      if (counted && said) {
        EXPECT_EQ(std::stoull(clause[2]), std::stoull(regimes[1]) + std::stoull(regimes[2])) << f.output;
        EXPECT_LE(std::stoull(clause[1]), std::stoull(clause[2])) << f.output;
      }
    }
  }
  if (!declared || r_s_required) {
    EXPECT_NEAR(f.r_s_Ohm / truth.r_s_Ohm, 1.0, 0.05) << what << "\n" << f.output;
  }
  std::printf("[ field    ] %s: psi_m %+.2f %%, r_s %+.2f %%%s\n", what.c_str(), 100.0 * (f.psi_m_Wb / truth.psi_m_Wb - 1.0),
              100.0 * (f.r_s_Ohm / truth.r_s_Ohm - 1.0), declared ? " (declared not identifiable)" : "");
}

TEST(CliVescFieldEstimate, OurEmulatorsFieldRide) {
  test::TempFile log("field.csv"), truth("field-truth.csv");
  const auto sim = test::run_command(rpem() + " sim --scenario " + test::source_dir() + "/scenarios/vesc-tool-field.yaml" +
                                     " --vesc-tool-out " + log.path() + " --vesc-tool-truth " + truth.path());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  // The truth file's last row: the plant's parameters (constant in this scenario).
  std::ifstream in(truth.path());
  std::string header, line, last;
  std::getline(in, header);
  ASSERT_EQ(header.rfind("ms_today,t_s,t_start_s,cycles,lost_before,psi_m,r_s,", 0), 0U) << header;
  while (std::getline(in, line)) last = line;
  std::stringstream s(last);
  std::string field;
  Truth t;
  for (int k = 0; k < 7 && std::getline(s, field, ','); ++k) {
    if (k == 5) t.psi_m_Wb = std::stod(field);
    if (k == 6) t.r_s_Ohm = std::stod(field);
  }
  ASSERT_GT(t.psi_m_Wb, 0.0);
  expect_field_accuracy(estimate(log.path(), config("vesc-6374-outrunner.yaml")), t, "vesc-tool-field");
  // Gauss–Newton on the same ride (docs/derivations.md §5, "One parameter of a steady-state sample"): where only ψ̂m
  // adapts, each window takes ψ̂m's own Newton step. The masked joint step threw ψ̂m from bound to bound wherever the
  // speed changed between windows (i_d = 0: R nearly singular) and ended at +63 % (2026-12-07); now −1.7 %.
  const Final gna = estimate(log.path(), config("vesc-6374-outrunner.yaml"), "--algorithm gna");
  EXPECT_NEAR(gna.psi_m_Wb / t.psi_m_Wb, 1.0, 0.02) << gna.output;
  EXPECT_EQ(gna.output.find("psi_m ended at its"), std::string::npos) << gna.output;
  std::printf("[ field    ] vesc-tool-field, gna: psi_m %+.2f %%\n", 100.0 * (gna.psi_m_Wb / t.psi_m_Wb - 1.0));
}

/// A log rewritten as a logger that writes VESC Tool's header prints it: every value it holds as a float with two
/// decimals (Arduino's Print::print(float); the ESP32/Arduino SD loggers that write this header print so), the
/// counters and times as integers.
void print_as_a_third_party_logger(const std::string& path) {
  std::istringstream in(test::read_file(path));
  std::string header, line, out;
  std::getline(in, header);
  out = header + "\n";
  std::vector<bool> integer;
  std::stringstream names(header);
  for (std::string name; std::getline(names, name, ';');) {
    integer.push_back(name == "ms_today" || name == "tachometer" || name == "tachometer_abs" || name == "fault_code" ||
                      name == "vesc_id" || name.rfind("ms_today_", 0) == 0 || name == "num_vescs" ||
                      name.rfind("gnss_", 0) == 0);
  }
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::size_t k = 0;
    for (std::string cell; std::getline(cells, cell, ';'); ++k) {
      if (k < integer.size() && !integer[k]) {
        char printed[64];
        std::snprintf(printed, sizeof printed, "%.2f", std::stod(cell));
        cell = printed;
      }
      out += cell + ";";
    }
    out += "\n";
  }
  std::ofstream(path) << out;
}

/// The independent generator's log (for config/vesc-6374-outrunner.yaml and `options`) written to `log`, and its
/// truth at the log's end (its thermal laws move R_s a little); zeros where the generator fails (said).
Truth independent_log(const std::string& options, const std::string& log) {
  test::TempFile truth("indep-truth.json");
  const auto gen = test::run_command(indep_vesc_log() + " --config " + config("vesc-6374-outrunner.yaml") + " " + options +
                                     " --out " + log + " --truth " + truth.path());
  EXPECT_EQ(gen.exit_code, 0) << gen.output;
  if (gen.exit_code != 0) return Truth{};
  const nlohmann::json j = nlohmann::json::parse(test::read_file(truth.path()));
  return Truth{j.at("true_at_end").at("psi_m_Wb").get<double>(), j.at("true_at_end").at("r_s_Ohm").get<double>()};
}

/// independent_log's estimate judged against its truth; `third_party`: printed as print_as_a_third_party_logger does.
void independent_case(const std::string& options, const std::string& what, bool r_s_required, bool third_party = false) {
  test::TempFile log("indep.csv");
  const Truth t = independent_log(options, log.path());
  if (third_party) print_as_a_third_party_logger(log.path());
  expect_field_accuracy(estimate(log.path(), config("vesc-6374-firmware.yaml")), t, what, r_s_required);
}

/// The log as a logger without d/q values writes it (docs/drive-log.md, "Logs without d/q values"): VESC Tool's
/// header with 0 in every d/q cell — an SD logger built on COMM_GET_VALUES that keeps the duty cycle, input voltage,
/// erpm and motor current — printing each as it does (the duty with 4 decimals, the voltage with 1, currents with 2,
/// erpm whole) and, with `every_other`, writing a row for every second read only (a logger polling twice as fast as
/// it writes: each row's means then span the read before only).
void print_as_a_logger_without_dq(const std::string& path, bool every_other) {
  std::istringstream in(test::read_file(path));
  std::string header, line, out;
  std::getline(in, header);
  out = header + "\n";
  std::vector<std::string> names;
  std::stringstream split(header);
  for (std::string name; std::getline(split, name, ';');) names.push_back(name);
  const auto printed = [](const std::string& name, const std::string& cell) -> std::string {
    const int decimals = name == "duty_cycle"                              ? 4
                         : name == "input_voltage"                         ? 1
                         : name == "current_motor" || name == "current_in" ? 2
                         : name == "erpm"                                  ? 0
                                                                           : -1;
    if (name == "d_axis_current" || name == "q_axis_current" || name == "d_axis_voltage" || name == "q_axis_voltage")
      return "0";
    if (decimals < 0) return cell;
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", decimals, std::stod(cell));
    return text;
  };
  for (std::size_t row = 0; std::getline(in, line); ++row) {
    if (every_other && row % 2 == 1) continue;
    std::stringstream cells(line);
    std::size_t k = 0;
    for (std::string cell; std::getline(cells, cell, ';'); ++k)
      out += (k < names.size() ? printed(names[k], cell) : cell) + ";";
    out += "\n";
  }
  std::ofstream(path) << out;
}

// The d/q values rebuilt from the duty cycle and the motor current (2026-12-01): seed 2 (zeros while off, across
// midnight) ψm −0.98 % (−1.18 % from its d/q values), R_s +15 %, declared not identifiable: a magnitude carries no
// back-EMF direction, so no lock test excludes the open-loop start-ups where R_s is excited; seed 1 written for every
// second read, ψm +0.34 %.
TEST(CliVescFieldEstimate, IndependentGeneratorWithoutDqValues) {
  test::TempFile log("indep-nodq.csv");
  const Truth t = independent_log("--seed 2 --psi-m-rel -0.15 --r-s-rel 0.2 --off-voltage zero --midnight", log.path());
  print_as_a_logger_without_dq(log.path(), false);
  const Final f = estimate(log.path(), config("vesc-6374-firmware.yaml"));
  EXPECT_NE(f.output.find("the log has no d/q values: i_d = 0, i_q = sign(duty)·i_motor"), std::string::npos) << f.output;
  expect_field_accuracy(f, t, "independent seed 2 without d/q values");
}

TEST(CliVescFieldEstimate, IndependentGeneratorWithoutDqValuesWrittenForEverySecondRead) {
  test::TempFile log("indep-nodq2.csv");
  const Truth t = independent_log("--seed 1 --duration-s 600 --psi-m-rel 0.2 --r-s-rel -0.25", log.path());
  print_as_a_logger_without_dq(log.path(), true);
  expect_field_accuracy(estimate(log.path(), config("vesc-6374-firmware.yaml")), t,
                        "independent seed 1 without d/q values, every second read");
}

TEST(CliVescFieldEstimate, IndependentGeneratorMeasuredBackEmf) {
  independent_case("--seed 1 --duration-s 600 --psi-m-rel 0.2 --r-s-rel -0.25", "independent seed 1", true);
}

TEST(CliVescFieldEstimate, IndependentGeneratorZerosWhileOffAcrossMidnight) {
  independent_case("--seed 2 --psi-m-rel -0.15 --r-s-rel 0.2 --off-voltage zero --midnight", "independent seed 2", true);
}

// Seed 1 as a third-party logger prints it (two decimals: the voltages in 10 mV steps). Its hard stop at 581.7 s
// (−32 000 erpm to standstill in 0.37 s at a constant 14 A) holds a window whose speed the PLL's reads rebuild
// 101 rad/s off (docs/derivations.md §13, "… where the acceleration changes"); with the coarser voltage no slope
// test flagged it, and that one window moved ψm by +7.8 %. It is transient now: ψm +0.01 %, R_s −0.4 % (2026-12-01;
// −3.4 % since the reads' speeds entered R_s' test, 2026-12-07, docs/derivations.md §13 "A stall's rocking").
TEST(CliVescFieldEstimate, IndependentGeneratorAsAThirdPartyLoggerPrintsIt) {
  independent_case("--seed 1 --duration-s 600 --psi-m-rel 0.2 --r-s-rel -0.25", "independent seed 1, two decimals", true,
                   true);
}

// A new user's walk (2026-12-06): a machine whose ψm lies above the configured D_M. The estimator holds ψ̂m at the
// bound, and rpem estimate printed the bound as the estimate, blaming the start ("its start still decides ±27 %").
// It says the estimate ended at the bound, which key to widen, and that it is no identification.
TEST(CliVescFieldEstimate, AMachineBeyondTheBoundsIsSaidToEndAtTheBound) {
  test::TempFile log("indep-bound.csv");
  const double psi_true = independent_log("--seed 1 --duration-s 600 --psi-m-rel 0.2 --r-s-rel -0.25", log.path()).psi_m_Wb;
  std::string cfg = test::read_file(config("vesc-6374-firmware.yaml"));
  const std::string bounds = "psi_m_Wb: [0.0023, 0.0070]";
  ASSERT_NE(cfg.find(bounds), std::string::npos);
  ASSERT_GT(psi_true, 0.0052);  // the machine above the bound below
  cfg.replace(cfg.find(bounds), bounds.size(), "psi_m_Wb: [0.0023, 0.0050]");
  test::TempFile narrow("narrow.yaml", cfg);
  const Final f = estimate(log.path(), narrow.path());
  EXPECT_NEAR(f.psi_m_Wb, 0.005, 1e-12) << f.output;
  EXPECT_NE(f.output.find("psi_m ended at its upper bound 0.005 Wb (estimator.bounds.psi_m_Wb: [0.0023, 0.005]), where "
                          "the estimator holds it: the machine's value may lie beyond it, so 0.005 Wb is no "
                          "identification; if the machine can have such a value, widen the bound"),
            std::string::npos)
      << f.output;
  EXPECT_EQ(f.output.find("psi_m not identifiable from this log: started at the ends"), std::string::npos) << f.output;
  // Within the configuration's bounds the same log says nothing of them.
  const Final wide = estimate(log.path(), config("vesc-6374-firmware.yaml"));
  EXPECT_EQ(wide.output.find("ended at its"), std::string::npos) << wide.output;
  EXPECT_NEAR(wide.psi_m_Wb / psi_true, 1.0, 0.02) << wide.output;
}

}  // namespace
}  // namespace rpem
