// rpemd's sources as a user starts them: the shipped vesc and signal_map configurations check out, and a
// signal map that lacks a quantity the estimator needs, or has a float signal that is not a whole IEEE 754
// value, stops rpemd at start with exit 78 (EX_CONFIG) and a message naming the map file and the reason.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>

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

TEST(CliRpemdSources, AMapWithoutSpeedStopsRpemdWithExit78NamingMapAndQuantity) {
  const rpem::test::TempFile map("rpemd-map-no-speed.yaml",
                                 "name: no-speed\nsample: {trigger: 0x301, averaged: true}\nframes:\n"
                                 "  - id: 0x301\n    signals:\n"
                                 "      - {field: i_d, start_bit: 0, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: A}\n"
                                 "      - {field: i_q, start_bit: 16, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: A}\n"
                                 "      - {field: u_d, start_bit: 32, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: V}\n"
                                 "      - {field: u_q, start_bit: 48, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: V}\n");
  const rpem::test::TempFile config("rpemd-map-no-speed-config.yaml",
                                    "daemon:\n  source:\n    type: signal_map\n    signal_map: {interface: vcan0, map: " +
                                        map.path() + "}\n");
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
    const rpem::test::TempFile map("rpemd-map-float.yaml", "name: float\nsample: {trigger: 0x302, averaged: true}\nframes:\n"
                                                         "  - id: 0x300\n    length: 16\n    signals:\n" +
                                                             std::string(signal) +
                                                             "      - {field: i_q, start_bit: 96, length: 32, value_type: float, unit: A}\n"
                                                             "  - id: 0x301\n    signals:\n" + rest);
    const rpem::test::TempFile config("rpemd-map-float-config.yaml",
                                      "daemon:\n  source:\n    type: signal_map\n    signal_map: {interface: vcan0, map: " +
                                          map.path() + "}\n");
    const auto r = rpem::test::run_command(rpemd() + " --check-config --config " + config.path());
    EXPECT_EQ(r.exit_code, 78) << r.output;
    EXPECT_NE(r.output.find("rpemd-map-float.yaml"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
  }
}

}  // namespace
