// rpemd's signal_map source without a socket (SignalMapSampler): the shipped maps' frames, written byte by
// byte from each map's documented layout (config/signal-maps/*.yaml), become samples of the kind the map
// gives — rotor-frame maps averaged samples, phase maps with the angle phase samples for DriveEstimator;
// ids the map does not name are ignored and counted; a map that lacks a needed quantity is refused when the
// configuration loads, naming the map file and the quantity.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <numbers>
#include <variant>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/signal_map_config.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

can::CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  can::CanFrame f;
  f.id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data.begin());
  return f;
}

can::SignalMap shipped(const char* name) { return io::load_signal_map(test::source_dir() + "/config/signal-maps/" + name); }

// Beckhoff AX8000 TxPDOs (little endian): 1500 rpm (15 000 000 in 0.0001 rpm); i_d −2 A (REAL32 0xC0000000),
// i_q 5 A (0x40A00000); u_d −3.5 V (0xC0600000), u_q 24 V (0x41C00000); u_dc 48000 mV (UINT32 0x0000BB80),
// T_winding 65.25 °C (REAL32: 1000001.01b = 1.00000101b·2^6, exponent 133 = 0x85 → 0 10000101 00000101 0… =
// 0x42828000). AM8141: 4 pole pairs.
TEST(SignalMapSource, ARotorFrameMapGivesAveragedSamplesAtTheTriggersTime) {
  SignalMapSampler s(shipped("beckhoff-ax8000-cia402.yaml"));
  ASSERT_EQ(s.kind(), SampleKind::kAveraged);
  SourceSample out;
  EXPECT_FALSE(s.on_frame(frame(0x181, {0xC0, 0xE1, 0xE4, 0x00}), 1000, out));
  EXPECT_FALSE(s.on_frame(frame(0x281, {0x00, 0x00, 0x00, 0xC0, 0x00, 0x00, 0xA0, 0x40}), 1100, out));
  EXPECT_FALSE(s.on_frame(frame(0x381, {0x00, 0x00, 0x60, 0xC0, 0x00, 0x00, 0xC0, 0x41}), 1200, out));
  EXPECT_FALSE(s.on_frame(frame(0x7E5, {0x01, 0x02}), 1250, out));  // not in the map (an LSS frame)
  ASSERT_TRUE(s.on_frame(frame(0x481, {0x80, 0xBB, 0x00, 0x00, 0x00, 0x80, 0x82, 0x42}), 1300, out));
  const auto* a = std::get_if<core::AveragedSample>(&out);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->t_ns, 1300);
  EXPECT_EQ(a->t_start_ns, 1300);  // instantaneous values (averaged: false)
  EXPECT_NEAR(a->omega_el_rad_s, 1500.0 * 2.0 * std::numbers::pi / 60.0 * 4.0, 1e-9);
  EXPECT_NEAR(a->i_dq_A[0], -2.0, 1e-12);
  EXPECT_NEAR(a->i_dq_A[1], 5.0, 1e-12);
  EXPECT_NEAR(a->u_dq_V[0], -3.5, 1e-12);
  EXPECT_NEAR(a->u_dq_V[1], 24.0, 1e-12);
  EXPECT_NEAR(a->u_dc_V, 48.0, 1e-12);
  EXPECT_EQ(a->t_winding_C, 65.25);  // exact in binary32
  EXPECT_EQ(s.counters().unknown_id, 1U);
  DiagnosticsRows rows;
  s.report(rows);
  EXPECT_EQ(rows.get(&diagnostics_t::can_unknown_id), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::can_frames), 5);
}

// rpem's native frames through a map (RPEM_TELEMETRY_A…E, docs/can-protocol.md; values little endian from
// bit 24): i_a 1 A, i_b −0.5 A, i_c −0.5 A, θ_el = 16384·2π/65536 = π/2, u_a 10 V, u_b −5 V, u_c −5 V,
// ω_el 100 rad/s, u_dc 48 V, the drive's time T_low 0x003039 µs = 12.345 ms (t_sample: the sample's time,
// not the receive time). At θ = π/2 the α-axis current (1 A) lies on −q: i_dq = (0, −1) A.
TEST(SignalMapSource, APhaseMapWithTheAngleGivesPhaseSamplesForDriveEstimator) {
  SignalMapSampler s(shipped("rpem-native-classic.yaml"));
  ASSERT_EQ(s.kind(), SampleKind::kPhase);
  SourceSample out;
  EXPECT_FALSE(s.on_frame(frame(0x110, {0, 0, 0, 0xE8, 0x03, 0x0C, 0xFE, 0}), 10, out));
  EXPECT_FALSE(s.on_frame(frame(0x111, {0, 0, 0, 0x0C, 0xFE, 0x00, 0x40, 0}), 20, out));
  EXPECT_FALSE(s.on_frame(frame(0x112, {0, 0, 0, 0xF4, 0x01, 0x06, 0xFF, 0}), 30, out));
  EXPECT_FALSE(s.on_frame(frame(0x113, {0, 0, 0, 0x06, 0xFF, 0xD0, 0x07, 0}), 40, out));
  ASSERT_TRUE(s.on_frame(frame(0x114, {0, 0, 0, 0x60, 0x09, 0x39, 0x30, 0x00}), 50, out));
  const auto* p = std::get_if<core::DriveSample>(&out);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->t_ns, 12'345'000);
  EXPECT_EQ(p->rx_ns, 50);
  EXPECT_NEAR(p->theta_el_rad, std::numbers::pi / 2.0, 1e-12);
  EXPECT_NEAR(p->omega_el_rad_s, 100.0, 1e-12);
  EXPECT_NEAR(p->u_dc_V, 48.0, 1e-12);
  EXPECT_EQ(p->current_frame, core::Frame::kDq);
  EXPECT_NEAR(p->i_A[0], 0.0, 1e-9);
  EXPECT_NEAR(p->i_A[1], -1.0, 1e-9);
  EXPECT_NEAR(p->u_V[0], 0.0, 1e-9);
  EXPECT_NEAR(p->u_V[1], -10.0, 1e-9);
}

TEST(SignalMapSource, TheShippedConfigurationsLoadWithTheirSourcesKind) {
  const DaemonConfig map = load_daemon_config(test::source_dir() + "/config/rpemd-signal-map.yaml");
  ASSERT_TRUE(std::holds_alternative<SignalMapSource::Options>(map.fixed.source));
  EXPECT_EQ(SourceCatalogue::sample_kind(map.fixed.source), SampleKind::kAveraged);
  EXPECT_TRUE(std::get<SignalMapSource::Options>(map.fixed.source).gives_u_dc);
  const DaemonConfig vesc = load_daemon_config(test::source_dir() + "/config/rpemd-vesc.yaml");
  ASSERT_TRUE(std::holds_alternative<VescSource::Options>(vesc.fixed.source));
  EXPECT_EQ(SourceCatalogue::sample_kind(vesc.fixed.source), SampleKind::kAveraged);
  const VescSource::Options& v = std::get<VescSource::Options>(vesc.fixed.source);
  EXPECT_EQ(v.controller_id, 17);
  EXPECT_EQ(v.host_id, 254);
  EXPECT_EQ(v.poll_rate_Hz, 200.0);
  EXPECT_EQ(vesc.fixed.lcm.channel_prefix, "VESC17_");
}

// A map without voltages: refused when the configuration loads, naming the map and what it lacks.
TEST(SignalMapSource, AMapWithoutANeededQuantityIsRefusedNamingFileAndQuantity) {
  const test::TempFile map(
      "no-voltage-map.yaml",
      "name: no-voltage\nsample: {trigger: 0x201, averaged: true}\nframes:\n"
      "  - id: 0x201\n    signals:\n"
      "      - {field: i_d, start_bit: 0, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: A}\n"
      "      - {field: i_q, start_bit: 16, length: 16, byte_order: little_endian, signed: true, scale: 0.01, unit: A}\n"
      "      - {field: erpm, start_bit: 32, length: 32, byte_order: little_endian, signed: true, scale: 1, unit: rpm}\n");
  const test::TempFile config(
      "rpemd-no-voltage.yaml",
      "daemon:\n  source:\n    type: signal_map\n    signal_map: {interface: can0, map: " + map.path() + "}\n");
  try {
    (void)load_daemon_config(config.path());
    FAIL() << "loaded";
  } catch (const io::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no-voltage-map.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("voltage (u_d and u_q"), std::string::npos) << what;
  }
}

// The source runs on the map the configuration checked: the file is read once, so a map removed (or edited)
// between the check and the start does not reach the loop.
TEST(SignalMapSource, RunsOnTheMapItsConfigurationChecked) {
  auto map = std::make_unique<test::TempFile>(
      "checked-map.yaml", test::read_file(test::source_dir() + "/config/signal-maps/beckhoff-ax8000-cia402.yaml"));
  const test::TempFile config(
      "rpemd-checked-map.yaml",
      "daemon:\n  source:\n    type: signal_map\n    signal_map: {interface: can0, map: " + map->path() + "}\n");
  const DaemonConfig c = load_daemon_config(config.path());
  const std::string map_path = map->path();
  map.reset();  // removed after the check
  ASSERT_FALSE(std::filesystem::exists(map_path));
  const auto source = SourceCatalogue::make(c.fixed.source);
  ASSERT_NE(source, nullptr);
  EXPECT_NE(source->name().find("checked-map.yaml"), std::string::npos) << source->name();
}

// An averaged source cannot be corrected for per-phase current errors: refused, naming the source.
TEST(SignalMapSource, PerPhaseCurrentCorrectionsAreRefusedOnAnAveragedSource) {
  std::ifstream paper(test::source_dir() + "/config/paper-ipmsm.yaml");
  const std::string machine((std::istreambuf_iterator<char>(paper)), std::istreambuf_iterator<char>());
  const test::TempFile config("rpemd-vesc-offsets.yaml",
                              machine +
                                  "model_extensions:\n  current_offset: [{phase: a, offset_A: 0.1}]\n"
                                  "daemon:\n  source:\n    type: vesc\n    vesc: {interface: can0, controller_id: 3}\n");
  try {
    (void)load_daemon_config(config.path());
    FAIL() << "loaded";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("source vesc, controller 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rpem::daemon
