// `rpem thermal fit` on a VESC Tool realtime log, as a user with a VESC runs it: the log is read as `rpem estimate`
// reads it (detected by its header, or through --log-map), its temp_motor is the winding sensor, and the thermal.yaml
// written is what `rpem estimate --thermal` runs on that log. The log comes from the independent generator
// (tests/independent_vesc/: its own firmware, link and thermal plant, none of rpem's forms), its winding cooling from
// 70 °C towards a 25 °C ambient over 15 minutes (a plain first-order element there, which two nodes can hold).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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

/// VESC Tool writes temp_motor with one decimal: the sensor's resolution [K].
constexpr double kSensorResolution_K = 0.1;

std::vector<std::string> cells(const std::string& line, char separator) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, separator);) out.push_back(cell);
  return out;
}

/// The last row's temp_motor of a VESC Tool log [°C].
double last_motor_temperature_C(const std::string& log) {
  std::ifstream f(log);
  std::string header, line, last;
  std::getline(f, header);
  while (std::getline(f, line)) {
    if (!line.empty()) last = line;
  }
  const std::vector<std::string> names = cells(header, ';'), values = cells(last, ';');
  for (std::size_t k = 0; k < names.size() && k < values.size(); ++k) {
    if (names[k] == "temp_motor") return std::stod(values[k]);
  }
  ADD_FAILURE() << "no temp_motor in " << log;
  return std::nan("");
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
      " --seed 3 --duration-s 900 --set thermal.winding_start_C=70 --set thermal.magnet_start_C=60 --out " + log);
  ASSERT_EQ(g.exit_code, 0) << g.output;

  const std::string fit = rpem_tool() + " thermal fit --log " + log + " --config " + outrunner_config();
  const test::ProcessResult r = test::run_command(fit + " --out " + dir_ + "/thermal.yaml --report " + dir_ + "/report");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("vesc.csv as VESC Tool realtime log (the header of VESC Tool 1.20 and later)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("has no T_coolant column"), std::string::npos) << r.output;
  // The outrunner's configuration says nothing of where its 25 mOhm were measured: the fit says what it assumed,
  // on the terminal and in thermal.yaml, where the user who reads it can correct it.
  const std::string assumed = "the copper law takes r_s_ref 0.025 Ohm at 20 °C, an assumption";
  EXPECT_NE(r.output.find("note: " + assumed), std::string::npos) << r.output;
  EXPECT_NE(test::read_file(dir_ + "/thermal.yaml").find("# note: " + assumed), std::string::npos);

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
  const test::ProcessResult e =
      test::run_command(rpem_tool() + " estimate --log " + log + " --config " + outrunner_config() + " --thermal " + dir_ +
                        "/thermal.yaml --out " + dir_ + "/estimate.csv");
  ASSERT_EQ(e.exit_code, 0) << e.output;
  const io::CsvTable estimate = io::CsvTable::read(dir_ + "/estimate.csv", true);
  ASSERT_GT(estimate.rows(), 0U);
  const double fused_C = estimate.column("t_winding_fused_C").back();
  EXPECT_NEAR(fused_C, last_motor_temperature_C(log), 5.0 * kSensorResolution_K);
}

}  // namespace
}  // namespace rpem
