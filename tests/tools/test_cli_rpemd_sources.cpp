// rpemd's sources as a user starts them: the shipped vesc and signal_map configurations and the configuration
// docs/rpemd.md gives in each source's section check out, and a
// signal map that lacks a quantity the estimator needs, or has a float signal that is not a whole IEEE 754
// value, stops rpemd at start with exit 78 (EX_CONFIG) and a message naming the map file and the reason.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <utility>

#include "support/child_process.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace {

std::string rpemd() { return rpem::test::binary_dir() + "/daemon/rpemd"; }

TEST(CliRpemdSources, ShippedVescAndSignalMapConfigurationsCheckOut) {
  for (const char* f : {"/config/rpemd-vesc.yaml", "/config/rpemd-signal-map.yaml"}) {
    const auto r = rpem::test::run_command(rpemd() + " --check-config --config " + rpem::test::source_dir() + f);
    EXPECT_EQ(r.exit_code, 0) << f << ": " << r.output;
    EXPECT_NE(r.output.find("is valid"), std::string::npos) << r.output;
  }
}

// --check-config checks what rpemd checks at start: with commands enabled and no command key rpemd refuses to start
// (exit 78), so --check-config refuses too where it sees the service's credentials ($CREDENTIALS_DIRECTORY,
// systemd's LoadCredential=), and says it did not check them where it does not; a bad command line is exit 64.
TEST(CliRpemdSources, CheckConfigChecksTheCommandKeysWhereItSeesThem) {
  const std::string config = rpem::test::source_dir() + "/config/rpemd-can.yaml";  // commands: {enabled: true}
  const auto outside =
      rpem::test::run_command("env -u CREDENTIALS_DIRECTORY " + rpemd() + " --check-config --config " + config);
  EXPECT_EQ(outside.exit_code, 0) << outside.output;
  EXPECT_NE(outside.output.find("the command keys are not checked here (CREDENTIALS_DIRECTORY is not set"),
            std::string::npos)
      << outside.output;
  EXPECT_NE(outside.output.find("is valid"), std::string::npos) << outside.output;
  const rpem::test::TempFile empty("credentials");
  std::filesystem::create_directories(empty.path());
  const auto service = rpem::test::run_command("CREDENTIALS_DIRECTORY=" + empty.path() + " " + rpemd() +
                                               " --check-config --config " + config);
  EXPECT_EQ(service.exit_code, 78) << service.output;
  EXPECT_NE(service.output.find("commands are enabled but no command key is configured"), std::string::npos)
      << service.output;
  EXPECT_EQ(service.output.find("is valid"), std::string::npos) << service.output;
  for (const char* bad : {" --bogus", " --can", " extra"}) {
    const auto r = rpem::test::run_command(rpemd() + bad);
    EXPECT_EQ(r.exit_code, 64) << bad << ": " << r.output;
  }
}

// --check-config reads the simulated drive's scenario as rpemd will: a missing file or a bad key in it is exit 78
// naming the scenario, not "is valid" and a source thread that fails later.
TEST(CliRpemdSources, CheckConfigReadsTheSimulatedDrivesScenario) {
  const std::string steady = rpem::test::read_file(rpem::test::source_dir() + "/scenarios/e2e-steady.yaml");
  ASSERT_NE(steady.find("duration_s: 20"), std::string::npos);
  const rpem::test::TempFile bad("bad-scenario.yaml",
                                 std::regex_replace(steady, std::regex("duration_s: 20"), "duration_z: 20"));
  for (const std::string& scenario : {std::string("/nonexistent/scenario.yaml"), bad.path()}) {
    const rpem::test::TempFile config("sim-scenario.yaml",
                                      "daemon:\n  source: {type: sim, sim: {scenario: " + scenario + "}}\n");
    const auto r = rpem::test::run_command(rpemd() + " --check-config --config " + config.path());
    EXPECT_EQ(r.exit_code, 78) << scenario << ": " << r.output;
    EXPECT_NE(r.output.find("cannot be run: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(scenario), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("is valid"), std::string::npos) << r.output;
  }
  const rpem::test::TempFile good("sim-good.yaml", "daemon:\n  source: {type: sim, sim: {scenario: " +
                                                       rpem::test::source_dir() + "/scenarios/e2e-steady.yaml}}\n");
  const auto ok = rpem::test::run_command(rpemd() + " --check-config --config " + good.path());
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
}

// A CAN interface that is not there (a typo, a module not loaded, a bus not brought up) is said in the journal once,
// naming it and why, and retried — not once per retry, and not in silence.
TEST(CliRpemdSources, AMissingCanInterfaceIsSaidOnceAndRetried) {
  const rpem::test::TempFile config("missing-can.yaml",
                                    "daemon:\n  machine_config: " + rpem::test::source_dir() +
                                        "/config/paper-ipmsm.yaml\n  source: {type: can, can: {interface: rpemnosuch0}}\n"
                                        "  loop: {realtime: off}\n  lcm: {url: \"udpm://239.255.76.67:7891?ttl=0\"}\n"
                                        "  status_interval_s: 0\n");
  const rpem::test::TempFile log("missing-can.log");
  {
    rpem::test::ChildProcess daemon({rpemd(), "--config", config.path()}, log.path());
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // ≈ 15 tries at the 100 ms reopen interval
  }
  const std::string text = rpem::test::read_file(log.path());
  const std::string said = "rpemd: rpemnosuch0: cannot read CAN: ";
  const auto first = text.find(said);
  ASSERT_NE(first, std::string::npos) << text;
  EXPECT_NE(text.find("retrying", first), std::string::npos) << text;
  EXPECT_EQ(text.find(said, first + 1), std::string::npos) << "said once, not per retry:\n" << text;
}

// Each "### `source: X`" section of docs/rpemd.md gives a complete configuration in its first yaml block; written
// beside the shipped config/ files (which its relative paths name, as a user's copy in config/ would), rpemd
// must accept it.
TEST(CliRpemdSources, EachSourceSectionOfTheDocsGivesAConfigurationThatChecksOut) {
  namespace fs = std::filesystem;
  const std::string doc = rpem::test::read_file(rpem::test::source_dir() + "/docs/rpemd.md");
  ASSERT_FALSE(doc.empty());
  const fs::path dir = rpem::test::temp_path("docs_source_configs");
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(rpem::test::source_dir() + "/config")) {
    fs::create_symlink(e.path(), dir / e.path().filename());
  }
  for (const char* type : {"can", "vesc", "signal_map", "sim"}) {
    const std::string heading = std::string("### `source: ") + type + "`";
    const auto at = doc.find(heading);
    ASSERT_NE(at, std::string::npos) << heading;
    const auto next = doc.find("\n### ", at + heading.size());
    const auto open = doc.find("```yaml\n", at);
    ASSERT_LT(open, next) << heading << ": no yaml block in the section";
    const auto body = open + 8;
    const auto close = doc.find("```", body);
    ASSERT_NE(close, std::string::npos) << heading;
    const fs::path file = dir / (std::string("docs-rpemd-") + type + ".yaml");
    std::ofstream(file) << doc.substr(body, close - body);
    const auto r = rpem::test::run_command(rpemd() + " --check-config --config " + file.string());
    EXPECT_EQ(r.exit_code, 0) << heading << ": " << r.output;
    EXPECT_NE(r.output.find("is valid"), std::string::npos) << heading << ": " << r.output;
    EXPECT_NE(doc.substr(body, close - body).find(std::string("type: ") + type), std::string::npos) << heading;
  }
  fs::remove_all(dir);
}

TEST(CliRpemdSources, AMapWithoutSpeedStopsRpemdWithExit78NamingMapAndQuantity) {
  const rpem::test::TempFile map(
      "rpemd-map-no-speed.yaml",
      "name: no-speed\nsample: {trigger: 0x301, averaged: true}\nframes:\n"
      "  - id: 0x301\n    signals:\n"
      "      - {field: i_d, start_bit: 0, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: A}\n"
      "      - {field: i_q, start_bit: 16, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: A}\n"
      "      - {field: u_d, start_bit: 32, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: V}\n"
      "      - {field: u_q, start_bit: 48, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: V}\n");
  const rpem::test::TempFile config(
      "rpemd-map-no-speed-config.yaml",
      "daemon:\n  source:\n    type: signal_map\n    signal_map: {interface: vcan0, map: " + map.path() + "}\n");
  for (const char* mode : {" --check-config", ""}) {  // refused before any socket or thread exists
    const auto r = rpem::test::run_command(rpemd() + mode + " --config " + config.path());
    EXPECT_EQ(r.exit_code, 78) << r.output;
    EXPECT_NE(r.output.find("rpemd-map-no-speed.yaml"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("speed (omega_el, erpm or speed_mech)"), std::string::npos) << r.output;
  }
}

TEST(CliRpemdSources, AFloatSignalOfTheWrongLengthOrAlignmentStopsRpemdWithExit78) {
  const std::string rest =
      "      - {field: u_d, start_bit: 0, length: 32, value_type: float, unit: V}\n"
      "      - {field: u_q, start_bit: 32, length: 32, value_type: float, unit: V}\n"
      "  - id: 0x302\n    signals:\n"
      "      - {field: erpm, start_bit: 0, length: 32, byte_order: little_endian, signed: true, unit: rpm}\n";
  const std::pair<const char*, const char*> cases[] = {
      {"      - {field: i_d, start_bit: 0, length: 16, value_type: float, unit: A}\n", "is 32 bits, not 16"},
      {"      - {field: i_d, start_bit: 4, length: 64, value_type: double, unit: A}\n", "must start on a byte boundary"},
  };
  for (const auto& [signal, why] : cases) {
    const rpem::test::TempFile map("rpemd-map-float.yaml",
                                   "name: float\nsample: {trigger: 0x302, averaged: true}\nframes:\n"
                                   "  - id: 0x300\n    length: 16\n    signals:\n" +
                                       std::string(signal) +
                                       "      - {field: i_q, start_bit: 96, length: 32, value_type: float, unit: A}\n"
                                       "  - id: 0x301\n    signals:\n" +
                                       rest);
    const rpem::test::TempFile config(
        "rpemd-map-float-config.yaml",
        "daemon:\n  source:\n    type: signal_map\n    signal_map: {interface: vcan0, map: " + map.path() + "}\n");
    const auto r = rpem::test::run_command(rpemd() + " --check-config --config " + config.path());
    EXPECT_EQ(r.exit_code, 78) << r.output;
    EXPECT_NE(r.output.find("rpemd-map-float.yaml"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
  }
}

}  // namespace
