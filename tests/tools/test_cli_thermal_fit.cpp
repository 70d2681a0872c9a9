// `rpem thermal fit` on a VESC Tool realtime log, as a user with a VESC runs it: the log is read as `rpem estimate`
// reads it (detected by its header, or through --log-map), its temp_motor is the winding sensor, and the thermal.yaml
// written is what `rpem estimate --thermal` runs on that log. The log comes from the independent generator
// (tests/independent_vesc/: its own firmware, link and thermal plant, none of rpem's forms), its winding cooling from
// 70 °C towards a 25 °C ambient over 15 minutes (a plain first-order element there, which two nodes can hold).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rpem/io/csv_table.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

std::string rpem_tool() { return test::binary_dir() + "/tools/rpem"; }
std::string outrunner_config() { return test::source_dir() + "/config/vesc-6374-outrunner.yaml"; }

/// The fit's note where nothing tests a log's soak (no winding reading at its start).
constexpr const char* kUntestedSoakNote =
    "note: the log has no winding reading at the start: that the machine starts soaked (every node at the coolant) is "
    "assumed, not tested, and the magnet law's reference is anchored on it";

/// VESC Tool writes temp_motor with one decimal: the sensor's resolution [K].
constexpr double kSensorResolution_K = 0.1;

std::vector<std::string> cells(const std::string& line, char separator) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, separator);) out.push_back(cell);
  return out;
}

/// A VESC Tool log's temp_motor [°C] per row, with the row's time of day [s] (ms_today).
struct MotorTemperatures {
  std::vector<double> t_s, t_motor_C;
};
MotorTemperatures motor_temperatures(const std::string& log) {
  std::ifstream f(log);
  std::string header, line;
  std::getline(f, header);
  const std::vector<std::string> names = cells(header, ';');
  const auto column = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return static_cast<std::size_t>(it - names.begin());
  };
  const std::size_t time = column("ms_today"), motor = column("temp_motor");
  MotorTemperatures out;
  if (time == names.size() || motor == names.size()) {
    ADD_FAILURE() << "no ms_today or temp_motor in " << log;
    return out;
  }
  while (std::getline(f, line)) {
    const std::vector<std::string> values = cells(line, ';');
    if (values.size() <= std::max(time, motor)) continue;
    out.t_s.push_back(std::stod(values[time]) / 1000.0);
    out.t_motor_C.push_back(std::stod(values[motor]));
  }
  return out;
}

/// The q-quantile (rank ⌊q·(n − 1)⌋) of the motor temperatures of the rows from `from_s` to `until_s`.
double motor_quantile(const MotorTemperatures& m, double from_s, double until_s, double q) {
  std::vector<double> v;
  for (std::size_t k = 0; k < m.t_s.size(); ++k) {
    if (m.t_s[k] >= from_s && m.t_s[k] <= until_s) v.push_back(m.t_motor_C[k]);
  }
  std::sort(v.begin(), v.end());
  return v.empty() ? std::nan("") : v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

/// A copy of a VESC Tool log whose temp_motor holds, from the row `fraction` of the way in, that row's cell: a sensor
/// that sticks (the cells copied as written).
void write_with_held_motor_temperature(const std::string& log, const std::string& out, double fraction) {
  std::ifstream f(log);
  std::vector<std::string> lines;
  for (std::string line; std::getline(f, line);) lines.push_back(line);
  ASSERT_GT(lines.size(), 3U);
  const std::vector<std::string> names = cells(lines[0], ';');
  const auto motor = static_cast<std::size_t>(std::find(names.begin(), names.end(), "temp_motor") - names.begin());
  ASSERT_LT(motor, names.size());
  const auto from = static_cast<std::size_t>(fraction * static_cast<double>(lines.size() - 1)) + 1;
  const std::string held = cells(lines[from], ';').at(motor);
  std::ofstream o(out);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    std::vector<std::string> values = cells(lines[k], ';');
    if (k >= from && values.size() > motor) values[motor] = held;
    for (std::size_t c = 0; c < values.size(); ++c) o << (c ? ";" : "") << values[c];
    if (!lines[k].empty() && lines[k].back() == ';') o << ';';  // a trailing separator, as VESC Tool writes it
    o << '\n';
  }
}

/// `rpem estimate --thermal` over a VESC Tool log of the outrunner, writing `out`: the fused winding of its last row
/// [°C] (NaN, with a failure, where it wrote none) and what it said.
struct FusedWindingEnd {
  double t_C = std::nan("");
  std::string said;
};
FusedWindingEnd fused_winding_at_end(const std::string& log, const std::string& thermal, const std::string& out) {
  FusedWindingEnd end;
  const test::ProcessResult e = test::run_command(rpem_tool() + " estimate --log " + log + " --config " +
                                                  outrunner_config() + " --thermal " + thermal + " --out " + out);
  end.said = e.output;
  if (e.exit_code != 0) {
    ADD_FAILURE() << e.output;
    return end;
  }
  const io::CsvTable estimate = io::CsvTable::read(out, true);
  if (estimate.rows() == 0) {
    ADD_FAILURE() << "no row in " << out;
    return end;
  }
  end.t_C = estimate.column("t_winding_fused_C").back();
  return end;
}

/// The winding sensor's signal of fit.json.
nlohmann::json winding_sensor_signal(const nlohmann::json& fit) {
  for (const nlohmann::json& s : fit.at("signals")) {
    if (s.at("name") == "winding sensor") return s;
  }
  ADD_FAILURE() << "no winding sensor in " << fit.at("signals").dump();
  return {};
}

/// How many of `rpem estimate --thermal`'s rows with a fused magnet (judged) hold the generator's true magnet of the row
/// before them (truth.json's rows) within ±2σ (covered).
struct BandCover {
  std::size_t judged = 0, covered = 0;
};
BandCover magnet_band_cover(const io::CsvTable& estimate, const nlohmann::json& truth) {
  const std::vector<double>& est_t = estimate.column("t");
  const std::vector<double>& fused = estimate.column("t_magnet_fused_C");
  const std::vector<double>& sd = estimate.column("t_magnet_fused_sd_C");
  const nlohmann::json& rows = truth.at("rows");
  const double t0_s = truth.at("start_ms_today").get<double>() / 1000.0;
  BandCover b;
  std::size_t k = 0;
  for (std::size_t n = 0; n < estimate.rows(); ++n) {
    if (!std::isfinite(fused[n])) continue;
    while (k + 1 < rows.size() && rows[k + 1].at("t_s").get<double>() <= est_t[n] - t0_s) ++k;
    ++b.judged;
    b.covered += std::abs(fused[n] - rows[k].at("T_magnet_C").get<double>()) <= 2.0 * sd[n] ? 1 : 0;
  }
  return b;
}

class CliThermalFit : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_path(std::string("cli_thermal_fit_") + ::testing::UnitTest::GetInstance()->current_test_info()->name())
               .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(CliThermalFit, ReadsAVescToolLogItsMotorSensorTheWinding) {
  const std::string log = dir_ + "/vesc.csv";
  const test::ProcessResult g = test::run_command(
      test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + outrunner_config() +
      " --seed 3 --duration-s 900 --set thermal.winding_start_C=70 --set thermal.magnet_start_C=60 --out " + log +
      " --truth " + dir_ + "/truth.json");
  ASSERT_EQ(g.exit_code, 0) << g.output;

  const std::string fit = rpem_tool() + " thermal fit --log " + log + " --config " + outrunner_config();
  const test::ProcessResult r = test::run_command(fit + " --out " + dir_ + "/thermal.yaml --report " + dir_ + "/report");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("vesc.csv as VESC Tool realtime log (the header of VESC Tool 1.20 and later)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("has no T_coolant column"), std::string::npos) << r.output;
  // Nor, so, a coolant that moves unread to measure (eq. 14.29b): said, and nothing written for it.
  EXPECT_NE(r.output.find("Coolant drift: the training part has no coolant readings"), std::string::npos) << r.output;
  EXPECT_EQ(test::read_file(dir_ + "/thermal.yaml").find("coolant_drift_K2_per_s"), std::string::npos);
  EXPECT_EQ(r.output.find("the winding is observed on no step"), std::string::npos) << r.output;  // temp_motor is
  // The outrunner's configuration says nothing of where its 25 mOhm were measured, and the generator's machine has
  // R_s 23 % above it: the fit anchors the copper law where the magnet law is anchored, at r̂s held there and the
  // winding sensor's reading (docs/thermal.md, "The copper law's reference"), and says so on the terminal and in
  // thermal.yaml, where the user who reads it can state a measured reference instead. The anchored r_s_ref at 20 °C
  // lies within the 5 % asked of r̂s (issue 23) of the generator's true R_s there (measured +0.9 %; the configured
  // 0.025 Ohm is −17 %).
  const std::string anchored = "the copper law's reference is anchored where the magnet law's is: r_s held there (";
  EXPECT_NE(r.output.find("note: " + anchored), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("the copper law takes r_s_ref 0.025 Ohm at 20 °C, an assumption"), std::string::npos);
  const std::string yaml = test::read_file(dir_ + "/thermal.yaml");
  EXPECT_NE(yaml.find("# note: " + anchored), std::string::npos);
  {
    const nlohmann::json truth = nlohmann::json::parse(test::read_file(dir_ + "/truth.json"));
    const double r_true = truth.at("true_machine").at("r_s_Ohm").get<double>();
    const double alpha = truth.at("thermal").at("r_s_coeff_per_K").get<double>();
    const double ref_C = truth.at("true_machine").at("reference_temperature_C").get<double>();
    std::smatch m;
    ASSERT_TRUE(std::regex_search(yaml, m, std::regex("copper: \\{r_s_ref_Ohm: ([0-9.e+-]+), reference_C: 20,"))) << yaml;
    EXPECT_NEAR(std::stod(m[1]) / (r_true * (1.0 + alpha * (20.0 - ref_C))), 1.0, 0.05) << yaml;
  }

  // Every step of the filter has the motor sensor, and the network fitted on the first 75 % follows the held-out
  // quarter of a 30 K cool-down open loop within a few of the sensor's quanta (measured 0.11 K RMS, 0.17 K worst).
  std::ifstream report(dir_ + "/report/fit.json");
  const nlohmann::json j = nlohmann::json::parse(report);
  const auto steps = j.at("steps").get<std::size_t>();
  EXPECT_GT(steps, 800U);  // 900 s at the filter's 1 s, less the start-up before the first adapted estimate
  bool sensor = false;
  for (const nlohmann::json& s : j.at("signals")) {
    if (s.at("name") != "winding sensor") continue;
    sensor = true;
    EXPECT_EQ(s.at("fit_points").get<std::size_t>() + s.at("heldout_points").get<std::size_t>(), steps);
    EXPECT_LE(s.at("heldout_rms_K").get<double>(), 5.0 * kSensorResolution_K);
    EXPECT_LE(s.at("heldout_worst_K").get<double>(), 5.0 * kSensorResolution_K);
  }
  EXPECT_TRUE(sensor) << j.at("signals").dump();

  // The built-in map given by hand reads the same log the same way: the same thermal.yaml, byte for byte.
  const test::ProcessResult mapped = test::run_command(fit + " --log-map " + test::source_dir() +
                                                       "/config/log-maps/vesc-tool.yaml --out " + dir_ + "/mapped.yaml");
  ASSERT_EQ(mapped.exit_code, 0) << mapped.output;
  EXPECT_EQ(test::read_file(dir_ + "/mapped.yaml"), test::read_file(dir_ + "/thermal.yaml"));

  // rpem estimate runs the fitted network over the log: the fused winding ends at the sensor's last reading.
  const FusedWindingEnd live_end = fused_winding_at_end(log, dir_ + "/thermal.yaml", dir_ + "/estimate.csv");
  EXPECT_NEAR(live_end.t_C, motor_temperatures(log).t_motor_C.back(), 5.0 * kSensorResolution_K);
  // A VESC Tool log has no coolant: rpem estimate says, as the fit does, what it took instead, on every sample.
  EXPECT_TRUE(std::regex_search(live_end.said, std::regex("rpem estimate: thermal: ([0-9]+) of \\1 samples have no "
                                                          "coolant temperature .*: the coolant is taken as")))
      << live_end.said;

  // The same log with a sensor that sticks a third of the way in (temp_motor holds that row's value to the end, the
  // winding cooling on): rpem estimate says it refused a held value (eq. 14.28) and the fused winding ends on the
  // live sensor's last reading within the network's own error (held out above: 0.17 K worst; 2 K allowed), not on the
  // held value ~10 K above it.
  const std::string stuck = dir_ + "/stuck.csv";
  write_with_held_motor_temperature(log, stuck, 1.0 / 3.0);
  const MotorTemperatures live = motor_temperatures(log), held = motor_temperatures(stuck);
  ASSERT_GT(held.t_motor_C.back() - live.t_motor_C.back(), 5.0);
  const FusedWindingEnd h = fused_winding_at_end(stuck, dir_ + "/thermal.yaml", dir_ + "/stuck_estimate.csv");
  EXPECT_NE(h.said.find("the winding sensor's reading was refused as a held value in "), std::string::npos) << h.said;
  EXPECT_NEAR(h.t_C, live.t_motor_C.back(), 2.0);

  // The fit on the stuck log itself (eq. 14.28c). r̂s adapts on no step of this ride, so nothing before the fit can
  // judge the column (eq. 14.28b); fitted to it, the network still moves the winding away from the held value, its
  // filter refuses it, and that value's run is set aside before the network is fitted again: the sensor's readings
  // kept are its live third (measured 275 of 821 steps; all 821 before), and rpem estimate with that network ends on
  // the live sensor's last reading within the same 2 K (measured 27.9 against 27.6 °C; 35.3 °C with the network
  // fitted to the held value).
  const test::ProcessResult sf =
      test::run_command(rpem_tool() + " thermal fit --log " + stuck + " --config " + outrunner_config() + " --out " + dir_ +
                        "/stuck_thermal.yaml --report " + dir_ + "/stuck_report");
  ASSERT_EQ(sf.exit_code, 0) << sf.output;
  // Said as one of the fit's notes: on the terminal, in thermal.yaml's header and in fit.json.
  const std::string said = "the winding sensor (T_winding) holds ";
  EXPECT_NE(sf.output.find("note: " + said), std::string::npos) << sf.output;
  EXPECT_NE(sf.output.find("eq. 14.28c): a held value, not a reading: not used; the network is fitted again without it"),
            std::string::npos)
      << sf.output;
  EXPECT_NE(test::read_file(dir_ + "/stuck_thermal.yaml").find("# note: " + said), std::string::npos);
  const nlohmann::json stuck_fit = nlohmann::json::parse(std::ifstream(dir_ + "/stuck_report/fit.json"));
  EXPECT_EQ(stuck_fit.at("notes").at(0).get<std::string>().rfind(said, 0), 0U) << stuck_fit.at("notes").dump();
  const auto stuck_steps = stuck_fit.at("steps").get<std::size_t>();
  const nlohmann::json kept = winding_sensor_signal(stuck_fit);
  const std::size_t readings_kept = kept.at("fit_points").get<std::size_t>() + kept.at("heldout_points").get<std::size_t>();
  EXPECT_GT(readings_kept, stuck_steps / 4);
  EXPECT_LT(readings_kept, stuck_steps / 2);
  EXPECT_NEAR(fused_winding_at_end(stuck, dir_ + "/stuck_thermal.yaml", dir_ + "/stuck_fit_estimate.csv").t_C,
              live.t_motor_C.back(), 2.0);
}

// What the training part observes, and what a fit that identifies nothing says of it. The cool-down above moves the
// winding by tens of kelvin: the span the fit reports is the log's own temp_motor between its 5th and 95th
// percentile over the training rows, within the difference a 1 s step's mean makes (the winding cools by at most
// 0.1 K/s) and one quantum; the fit says the temperatures move. The same ride with the plant's temperatures held
// (--isothermal) moves nothing: the fit says no temperature moves beyond its noise, and why nothing is identified.
TEST_F(CliThermalFit, SaysWhatTheTrainingPartObserves) {
  const std::string outrunner = " --config " + outrunner_config();
  for (const bool isothermal : {false, true}) {
    SCOPED_TRACE(isothermal ? "isothermal" : "cooling");
    const std::string log = dir_ + (isothermal ? "/isothermal.csv" : "/cooling.csv");
    const test::ProcessResult g = test::run_command(
        test::binary_dir() + "/tests/independent_vesc/indep_vesc_log" + outrunner + " --seed 3 --duration-s 600 " +
        (isothermal ? "--isothermal" : "--set thermal.winding_start_C=70 --set thermal.magnet_start_C=60") + " --out " +
        log);
    ASSERT_EQ(g.exit_code, 0) << g.output;
    const std::string report = dir_ + (isothermal ? "/isothermal" : "/cooling");
    const test::ProcessResult r = test::run_command(rpem_tool() + " thermal fit --log " + log + outrunner + " --out " +
                                                    report + ".yaml --report " + report);
    if (isothermal) {
      // Nothing identified, the network is its prior's; with the copper law anchored at r̂s (R_s 14 % above the
      // configured, as the generator's machine has it) that prior's winding runs away at the rated current, and
      // thermal.yaml is refused as such (exit 65); the report is written all the same.
      EXPECT_EQ(r.exit_code, 65) << r.output;
      EXPECT_NE(r.output.find("not written: the network has no steady state at the machine's rated point"),
                std::string::npos)
          << r.output;
    } else {
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    std::ifstream json(report + "/fit.json");
    const nlohmann::json j = nlohmann::json::parse(json);
    const nlohmann::json sensor = winding_sensor_signal(j);
    // The training part: from the first step's start (the filter steps from the first adapted estimate on; each
    // step's time in predictions.csv is its end, a step 1 s long) to fit_until_s.
    std::ifstream predictions(report + "/predictions.csv");
    std::string header, first;
    ASSERT_TRUE(std::getline(predictions, header) && std::getline(predictions, first) && header.rfind("t,", 0) == 0);
    const double from_s = std::stod(cells(first, ',').front()) - 1.0, until_s = j.at("fit_until_s").get<double>();
    const MotorTemperatures m = motor_temperatures(log);
    const double low_C = motor_quantile(m, from_s, until_s, 0.05), high_C = motor_quantile(m, from_s, until_s, 0.95);
    EXPECT_NEAR(sensor.at("training_low_C").get<double>(), low_C, 2.0 * kSensorResolution_K);
    EXPECT_NEAR(sensor.at("training_high_C").get<double>(), high_C, 2.0 * kSensorResolution_K);
    // The σ the fit weighs the sensor with: the default 1 K beside the fit's 0.5 K floor.
    EXPECT_NEAR(sensor.at("training_sigma_K").get<double>(), std::hypot(1.0, 0.5), 1e-9);
    if (isothermal) {
      EXPECT_LE(high_C - low_C, kSensorResolution_K + 1e-9);  // one quantum at most
      EXPECT_NE(r.output.find("note: no parameter is identified: no temperature the training part observes moves beyond "
                              "its noise"),
                std::string::npos)
          << r.output;
    } else {
      EXPECT_GT(high_C - low_C, 20.0);
      EXPECT_EQ(r.output.find("moves beyond its noise"), std::string::npos) << r.output;
    }
    // The terminal's line of the signal says the same span.
    char line[96];
    std::snprintf(line, sizeof line, "winding sensor: %.1f–%.1f °C in training", sensor.at("training_low_C").get<double>(),
                  sensor.at("training_high_C").get<double>());
    EXPECT_NE(r.output.find(line), std::string::npos) << r.output;

    // Trained only on the steps before the first magnet observation: the magnet's signal is held out alone, and
    // the fit says the training part has none of it (not a span of zeros).
    if (isothermal) continue;
    const std::vector<std::string> names = cells(header, ',');
    const auto observed =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), "T_magnet_observed") - names.begin());
    ASSERT_LT(observed, names.size()) << header;
    double first_magnet_s = std::nan("");
    for (std::string row; std::getline(predictions, row);) {
      const std::vector<std::string> c = cells(row, ',');
      if (c.size() > observed && !c[observed].empty()) {
        first_magnet_s = std::stod(c[0]);
        break;
      }
    }
    ASSERT_TRUE(std::isfinite(first_magnet_s));
    const double until_magnet_s = first_magnet_s - 1.5;
    ASSERT_GT(until_magnet_s - from_s, 12.0);  // at least the fit's 10 steps before it
    const test::ProcessResult early =
        test::run_command(rpem_tool() + " thermal fit --log " + log + outrunner + " --out " + report +
                          "_early.yaml --fit-until-s " + std::to_string(until_magnet_s));
    ASSERT_EQ(early.exit_code, 0) << early.output;
    EXPECT_NE(early.output.find("magnet (from psi_m): none in training"), std::string::npos) << early.output;
    EXPECT_NE(test::read_file(report + "_early.yaml").find("# magnet (from psi_m): none in training"), std::string::npos);
    // A part without points has no figure, not one of 0 K.
    const std::size_t at = early.output.find("magnet (from psi_m): none in training");
    EXPECT_EQ(early.output.substr(at, early.output.find('\n', at) - at).find("fit "), std::string::npos) << early.output;
    EXPECT_EQ(test::read_file(report + "_early.yaml").find("K RMS (0)"), std::string::npos);
  }
}

// A log that does not start soaked (the VESC ride above: winding 70 °C, magnet 60 °C, ambient 25 °C). The magnet law's
// reference is anchored at the first magnet observations, whose temperature a soaked start gives (the coolant); here
// the winding sensor shows the start is not (44.9 K above the coolant, 1 K sensor), and the magnet's temperature is
// unknown. Anchored at the coolant, as before, every magnet temperature read 35 K cold with a σ of 4 K: the true
// magnet outside the band on every row, on the side a derating fails. Now the fit says so, anchors at the winding's
// reading and widens the reference's σ to the winding's distance from the coolant: the band holds the true magnet
// (the generator's truth, its own thermal plant) on at least 90 % of the rows, and the anchored ψ_ref is within
// the error that σ allows, |α|·44.9 K ≈ 5.4 %, of the true one.
TEST_F(CliThermalFit, ALogThatDoesNotStartSoakedIsAnchoredAtItsWindingWithTheBandWidened) {
  const std::string log = dir_ + "/vesc.csv", truth = dir_ + "/truth.json";
  const test::ProcessResult g = test::run_command(
      test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + outrunner_config() +
      " --seed 3 --duration-s 900 --set thermal.winding_start_C=70 --set thermal.magnet_start_C=60 --out " + log +
      " --truth " + truth);
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const test::ProcessResult r = test::run_command(rpem_tool() + " thermal fit --log " + log + " --config " +
                                                  outrunner_config() + " --out " + dir_ + "/thermal.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: the log does not start soaked: at its first step the winding sensor reads 69.9 °C, "
                          "44.9 K from the coolant's 25.0 °C"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("no winding reading at the start"), std::string::npos) << r.output;  // its soak is tested
  // A VESC Tool log has no coolant column: the coolant judged against is a constant, which the note says may be the
  // one that is off (a cold log read against a warm constant showed as "not soaked" with no other reading offered).
  EXPECT_NE(r.output.find("note: the log has no coolant column: the 25.0 °C it is judged against is thermal.coolant_C, "
                          "not a measurement"),
            std::string::npos)
      << r.output;
  const std::string yaml = test::read_file(dir_ + "/thermal.yaml");
  const std::size_t law = yaml.find("magnet_law: {psi_m_ref_Wb: ");
  ASSERT_NE(law, std::string::npos) << yaml;
  const double psi_ref_Wb = std::stod(yaml.substr(law + 27));
  const std::size_t sigma = yaml.find("reference_sigma_K: ", law);
  ASSERT_NE(sigma, std::string::npos) << yaml;
  EXPECT_NEAR(std::stod(yaml.substr(sigma + 19)), 44.9, 0.05);

  const nlohmann::json t = nlohmann::json::parse(std::ifstream(truth));
  const nlohmann::json& plant = t.at("thermal");
  const double true_ref_Wb = t.at("true_machine").at("psi_m_Wb").get<double>() *
                             (1.0 + plant.at("psi_m_coeff_per_K").get<double>() *
                                        (20.0 - t.at("true_machine").at("reference_temperature_C").get<double>()));
  EXPECT_NEAR(psi_ref_Wb / true_ref_Wb - 1.0, 0.0, 0.0012 * 44.9) << psi_ref_Wb << " against " << true_ref_Wb;

  const test::ProcessResult e =
      test::run_command(rpem_tool() + " estimate --log " + log + " --config " + outrunner_config() + " --thermal " + dir_ +
                        "/thermal.yaml --out " + dir_ + "/estimate.csv");
  ASSERT_EQ(e.exit_code, 0) << e.output;
  EXPECT_EQ(e.output.find("starts soaked, every node"), std::string::npos) << e.output;  // its sensor tests the soak
  const BandCover band = magnet_band_cover(io::CsvTable::read(dir_ + "/estimate.csv", true), t);
  ASSERT_GT(band.judged, 500U);
  EXPECT_GE(static_cast<double>(band.covered), 0.9 * static_cast<double>(band.judged))
      << band.covered << " of " << band.judged;
}

// A warm start without a winding sensor (found by a new user's walk, docs/thermal.md): rpemd's demo drive, whose
// winding starts at 45 °C and rises as 45 + 50·(1 − e^(−t/400 s)) °C (scenarios/rpemd-demo.yaml, scripted, not a
// loss-driven plant), its averaged log without temperature columns against the 25 °C coolant constant. Nothing tests
// the soak the magnet's anchor assumes; the fit says so, and says where r̂s, adapting at the standstills with current,
// first puts the winding: within 1 K of the script's winding at that time (r̂s's step mean, measured 0.2 K off).
TEST_F(CliThermalFit, ALogWithoutAWindingReadingSaysItsSoakIsAssumedAndWhereRsFirstPutsTheWinding) {
  const std::string log = dir_ + "/demo.csv";
  const test::ProcessResult g =
      test::run_command(rpem_tool() + " sim --scenario " + test::source_dir() +
                        "/scenarios/rpemd-demo.yaml --averaged-out " + log + " --averaged-rate 100");
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const test::ProcessResult r =
      test::run_command(rpem_tool() + " thermal fit --log " + log + " --config " + test::source_dir() +
                        "/config/paper-ipmsm.yaml --out " + dir_ + "/thermal.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(kUntestedSoakNote), std::string::npos) << r.output;
  const std::string head = "r_s's first reading puts the winding at ";
  const std::size_t at = r.output.find(head);
  ASSERT_NE(at, std::string::npos) << r.output;
  const double winding_C = std::stod(r.output.substr(at + head.size()));
  const std::size_t in = r.output.find(" s in (through the copper law's reference, itself assumed)", at);
  ASSERT_NE(in, std::string::npos) << r.output;
  const std::size_t from = r.output.rfind(", ", in);
  const double t_s = std::stod(r.output.substr(from + 2, in - from - 2));
  EXPECT_LE(t_s, 300.0);
  EXPECT_NEAR(winding_C, 45.0 + 50.0 * (1.0 - std::exp(-t_s / 400.0)), 1.0) << r.output;
  EXPECT_GT(winding_C - 25.0, 15.0);  // the reading says the start was warm
  // rpem estimate --thermal starts its filter soaked too, and says that it assumes it.
  const test::ProcessResult e =
      test::run_command(rpem_tool() + " estimate --log " + log + " --config " + test::source_dir() +
                        "/config/paper-ipmsm.yaml --thermal " + dir_ + "/thermal.yaml --out " + dir_ + "/estimate.csv");
  ASSERT_EQ(e.exit_code, 0) << e.output;
  EXPECT_NE(e.output.find("thermal: note: the thermal network starts soaked, every node at the coolant, an assumption: "
                          "the log gives no winding reading the filter fuses"),
            std::string::npos)
      << e.output;
  // A ratio prints without a unit ("= 1.25", not "= 1.25 1").
  const std::size_t scale = r.output.find("copper loss scale = ");
  ASSERT_NE(scale, std::string::npos) << r.output;
  const std::string after = r.output.substr(scale + 20, r.output.find('\n', scale) - scale - 20);
  EXPECT_EQ(after.find(" 1 ("), std::string::npos) << after;
  EXPECT_NE(after.find(" ("), std::string::npos) << after;
}

// A VESC without a motor sensor: its NTC input open, the firmware filters in −100 °C for the reading it does not have
// (vedderb/bldc motor/mc_interface.c, update_override_limits; the generator does as the firmware, its README), so
// temp_motor is −100 on every row. Read as a winding at −100 °C, the log seemed 125 K below its coolant at the start:
// the fit anchored the magnet law there (the magnet observed at −108…−100 °C) and wrote no network. It is read as a
// log without a winding sensor: the fit says so and fits without one. The ride: soaked at the coolant's 25 °C, 7 min at
// 40 A against an eddy-current brake (the generator's plant heats the winding to 57 °C and the magnet to 33 °C),
// then coasting. The fused magnet's band holds the generator's true magnet on at least 90 % of the rows (measured:
// all, RMS 3.9 K), and the fused winding never falls below the coolant it starts at, less 1 K (the losses only heat a
// soaked machine; measured: 25.0 °C).
TEST_F(CliThermalFit, AVescWithoutAMotorSensorIsReadAsALogWithoutOne) {
  const std::string log = dir_ + "/vesc.csv", truth = dir_ + "/truth.json", scenario = dir_ + "/heat.csv";
  std::ofstream(scenario) << "kind,duration_s,current_A,ramp_s,until_erpm,erpm_per_s,external_Nm,friction_Nm,viscous_Nm_s\n"
                             "off,2,0,0,0,1000,0,0,0\ncurrent,420,40,1,0,1000,0,0,0.0073\ncoast,170,0,0,0,1000,0,0,0\n";
  const test::ProcessResult g =
      test::run_command(test::binary_dir() + "/tests/independent_vesc/indep_vesc_log --config " + outrunner_config() +
                        " --seed 3 --duration-s 600" + " --scenario " + scenario +
                        " --set sensors.motor_sensor_fitted=0 --out " + log + " --truth " + truth);
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const MotorTemperatures m = motor_temperatures(log);
  ASSERT_FALSE(m.t_motor_C.empty());
  for (const double t : m.t_motor_C) ASSERT_EQ(t, -100.0);

  const test::ProcessResult r =
      test::run_command(rpem_tool() + " thermal fit --log " + log + " --config " + outrunner_config() + " --out " + dir_ +
                        "/thermal.yaml --report " + dir_ + "/report");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("temp_motor (T_winding) holds -100 degC, its logger's value for no reading, on every row: no "
                          "such sensor, read as absent"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("note: the log does not start soaked"), std::string::npos) << r.output;
  // Without a winding reading nothing tests the soak the anchor takes: the fit says it assumes it.
  EXPECT_NE(r.output.find(kUntestedSoakNote), std::string::npos) << r.output;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(dir_ + "/report/fit.json"));
  for (const nlohmann::json& s : j.at("signals")) EXPECT_NE(s.at("name"), "winding sensor") << j.at("signals").dump();
  // Nor does r̂s adapt in the training part of this ride at speed: the fit says its winding is unchecked.
  bool winding_observed = false;
  for (const nlohmann::json& s : j.at("signals")) {
    winding_observed |= s.at("name").get<std::string>().rfind("winding", 0) == 0 && s.at("fit_points").get<int>() > 0;
  }
  EXPECT_FALSE(winding_observed) << j.at("signals").dump();
  EXPECT_NE(r.output.find("note: the winding is observed on no step of the training part"), std::string::npos) << r.output;

  const test::ProcessResult e =
      test::run_command(rpem_tool() + " estimate --log " + log + " --config " + outrunner_config() + " --thermal " + dir_ +
                        "/thermal.yaml --out " + dir_ + "/estimate.csv");
  ASSERT_EQ(e.exit_code, 0) << e.output;
  const io::CsvTable estimate = io::CsvTable::read(dir_ + "/estimate.csv", true);
  for (const double w : estimate.column("t_winding_fused_C")) {
    if (std::isfinite(w)) {
      EXPECT_GE(w, 25.0 - 1.0);
    }
  }
  const BandCover band = magnet_band_cover(estimate, nlohmann::json::parse(std::ifstream(truth)));
  ASSERT_GT(band.judged, 500U);
  EXPECT_GE(static_cast<double>(band.covered), 0.9 * static_cast<double>(band.judged))
      << band.covered << " of " << band.judged;
}

}  // namespace
}  // namespace rpem
