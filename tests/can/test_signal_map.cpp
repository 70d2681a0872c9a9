// Signal maps: DBC bit extraction against hand-worked vectors (Intel and Motorola, signed and unsigned),
// the example maps in config/signal-maps/ against frames written byte by byte (CiA 402 PDOs) and against
// the native telemetry decoder on the same frames (two independent decoders must agree), bad input
// counted, and maps that cannot be used refused at load with file:line and the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "rpem/can/signal_map.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/signal_map_config.hpp"
#include "support/temp_file.hpp"
#include "support_can.hpp"

namespace rpem::can {
namespace {

CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data.begin());
  return f;
}

std::string example(const std::string& name) { return test::source_dir() + "/config/signal-maps/" + name; }

TEST(SignalMapBits, IntelAndMotorolaAsDbcDefinesThem) {
  // Intel (@1): start bit = LSB; a 12-bit signal at bit 4 of C0 AB is (0xABC0 >> 4) = 0xABC.
  SignalSpec intel{SampleField::kIdA, 4, 12, false, false, 1.0, 0.0};
  EXPECT_EQ(extract_raw(frame(1, {0xC0, 0xAB}), intel), 0xABC);
  intel.is_signed = true;
  EXPECT_EQ(extract_raw(frame(1, {0xC0, 0xAB}), intel), 0xABC - 0x1000);
  // Motorola (@0): start bit = MSB in DBC numbering; 12 bits from bit 7 of AB C0 are AB then C → 0xABC.
  SignalSpec motorola{SampleField::kIdA, 7, 12, true, false, 1.0, 0.0};
  EXPECT_EQ(extract_raw(frame(1, {0xAB, 0xC0}), motorola), 0xABC);
  // A 16-bit Motorola signal starting mid-byte: start bit 3, bits 3..0 of byte 0, all of byte 1, 7..4 of byte 2.
  SignalSpec mid{SampleField::kIdA, 3, 16, true, true, 1.0, 0.0};
  EXPECT_EQ(extract_raw(frame(1, {0x0F, 0xED, 0xC0}), mid), static_cast<std::int16_t>(0xFEDC));
  // 64-bit little endian.
  SignalSpec wide{SampleField::kIdA, 0, 64, false, true, 1.0, 0.0};
  EXPECT_EQ(extract_raw(frame(1, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}), wide), -1);
}

TEST(SignalMapExamples, CiA402Ax8000PdosGiveTheSample) {
  const SignalMap map = io::load_signal_map(example("beckhoff-ax8000-cia402.yaml"));
  SignalMapDecoder dec(map);
  core::AveragedSample s;
  EXPECT_FALSE(dec.decode(frame(0x181, {0xDC, 0x05, 0x00, 0x00}), 1000, s));  // 1500 rpm
  EXPECT_FALSE(dec.decode(frame(0x281, {0x3C, 0xF6, 0xFF, 0xFF, 0x39, 0x30, 0x00, 0x00}), 1000, s));  // −2.5 A, 12.345 A
  EXPECT_FALSE(dec.decode(frame(0x381, {0xE0, 0xB1, 0xFF, 0xFF, 0xE4, 0x4B, 0x02, 0x00}), 1000, s));  // −20 V, 150.5 V
  EXPECT_FALSE(dec.decode(frame(0x701, {0x05}), 1000, s));  // heartbeat: not mapped, ignored
  ASSERT_TRUE(dec.decode(frame(0x481, {0x80, 0x8B, 0x08, 0x00, 0xD5, 0x02}), 2000, s));  // 560 V, 72.5 °C
  EXPECT_DOUBLE_EQ(s.omega_el_rad_s, 1500.0 * 2.0 * std::numbers::pi / 60.0 * 4);
  EXPECT_DOUBLE_EQ(s.i_dq_A[0], -2.5);
  EXPECT_DOUBLE_EQ(s.i_dq_A[1], 12.345);
  EXPECT_DOUBLE_EQ(s.u_dq_V[0], -20.0);
  EXPECT_DOUBLE_EQ(s.u_dq_V[1], 150.5);
  EXPECT_DOUBLE_EQ(s.u_dc_V, 560.0);
  EXPECT_DOUBLE_EQ(s.t_winding_C, 72.5);
  EXPECT_TRUE(std::isnan(s.t_magnet_C));
  EXPECT_EQ(s.t_ns, 2000);
  EXPECT_EQ(s.t_start_ns, 2000);  // instantaneous
  EXPECT_TRUE(s.gap_before);      // the first sample
  EXPECT_EQ(dec.counters().unknown_id, 1U);
  EXPECT_EQ(dec.counters().samples, 1U);

  // A SYNC cycle that lost TxPDO3: the trigger finds no voltage, the sample is incomplete and the next
  // one carries a gap.
  EXPECT_FALSE(dec.decode(frame(0x181, {0xDC, 0x05, 0x00, 0x00}), 3000, s));
  EXPECT_FALSE(dec.decode(frame(0x281, {0x3C, 0xF6, 0xFF, 0xFF, 0x39, 0x30, 0x00, 0x00}), 3000, s));
  EXPECT_FALSE(dec.decode(frame(0x481, {0x80, 0x8B, 0x08, 0x00, 0xD5, 0x02}), 3000, s));
  EXPECT_EQ(dec.counters().incomplete, 1U);
  EXPECT_FALSE(dec.decode(frame(0x281, {0x3C, 0xF6, 0xFF}), 4000, s));  // too short
  EXPECT_EQ(dec.counters().wrong_length, 1U);
}

TEST(SignalMapExamples, NativeFramesThroughTheMapAgreeWithTheNativeDecoder) {
  const SignalMap map = io::load_signal_map(example("rpem-native-classic.yaml"));
  std::mt19937_64 rng(3);
  std::vector<core::DriveSample> samples;
  for (int k = 0; k < 50; ++k) {
    core::DriveSample s = test::random_sample(rng, 1'000'000 + k * 125'000LL);
    const double sum = (s.i_A[0] + s.i_A[1] + s.i_A[2]) / 3.0;  // a balanced machine
    s.i_A -= core::Vec3::Constant(sum);
    samples.push_back(s);
  }
  TelemetryEncoder enc(BusMode::kClassic);
  const std::vector<CanFrame> frames = test::encode_all(enc, samples);
  TelemetryDecoder native;
  const std::vector<core::DriveSample> reference = test::decode_all(native, frames);
  ASSERT_EQ(reference.size(), samples.size());

  SignalMapDecoder dec(map);
  std::vector<core::AveragedSample> got;
  core::AveragedSample s;
  for (const CanFrame& f : frames) {
    if (dec.decode(f, 0, s)) got.push_back(s);
  }
  ASSERT_EQ(got.size(), reference.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    const core::DriveSample& r = reference[k];
    const core::Rotation rot = core::Rotation::of(r.theta_el_rad);
    const core::Vec2 i = core::park(core::clarke(r.i_A), rot), u = core::park(core::clarke(r.u_V), rot);
    EXPECT_NEAR(got[k].i_dq_A[0], i[0], 1e-9);
    EXPECT_NEAR(got[k].i_dq_A[1], i[1], 1e-9);
    EXPECT_NEAR(got[k].u_dq_V[0], u[0], 1e-9);
    EXPECT_NEAR(got[k].u_dq_V[1], u[1], 1e-9);
    EXPECT_NEAR(got[k].omega_el_rad_s, r.omega_el_rad_s, 1e-9);
    EXPECT_NEAR(got[k].u_dc_V, r.u_dc_V, 1e-9);
  }
  EXPECT_EQ(dec.counters().incomplete, 0U);
}

TEST(SignalMapExamples, AveragedMapsSpanTheWindowSinceThePreviousSample) {
  const std::string text =
      "name: lisp\nsample: {trigger: 0x12345, extended: true, averaged: true}\nframes:\n"
      "  - {id: 0x12345, extended: true, signals: [\n"
      "      {field: i_d, start_bit: 7, length: 16, byte_order: big_endian, signed: true, scale: 0.01, unit: A},\n"
      "      {field: i_q, start_bit: 23, length: 16, byte_order: big_endian, signed: true, scale: 0.01, unit: A},\n"
      "      {field: u_d, start_bit: 39, length: 8, byte_order: big_endian, signed: true, scale: 0.1, unit: V},\n"
      "      {field: u_q, start_bit: 47, length: 8, byte_order: big_endian, signed: true, scale: 0.1, unit: V},\n"
      "      {field: erpm, start_bit: 55, length: 16, byte_order: big_endian, signed: true, scale: 1, unit: rpm}]}\n";
  SignalMapDecoder dec(io::parse_signal_map(text, "lisp.yaml"));
  CanFrame f = frame(0x12345, {0x01, 0x2C, 0xFF, 0x38, 0x0A, 0x9C, 0x4E, 0x20});
  f.extended = true;
  core::AveragedSample s;
  ASSERT_TRUE(dec.decode(f, 5'000'000, s));
  EXPECT_EQ(s.t_start_ns, 5'000'000);
  ASSERT_TRUE(dec.decode(f, 9'000'000, s));
  EXPECT_EQ(s.t_start_ns, 5'000'000);
  EXPECT_FALSE(s.gap_before);
  EXPECT_DOUBLE_EQ(s.i_dq_A[0], 3.0);
  EXPECT_DOUBLE_EQ(s.i_dq_A[1], -2.0);
  EXPECT_DOUBLE_EQ(s.u_dq_V[0], 1.0);
  EXPECT_DOUBLE_EQ(s.u_dq_V[1], -10.0);
  EXPECT_DOUBLE_EQ(s.omega_el_rad_s, 20000.0 * 2.0 * std::numbers::pi / 60.0);
  CanFrame standard = f;
  standard.extended = false;  // same number, standard ID: another frame
  EXPECT_FALSE(dec.decode(standard, 10'000'000, s));
  EXPECT_EQ(dec.counters().unknown_id, 1U);
}

void expect_refused(const std::string& text, const std::string& what) {
  try {
    (void)io::parse_signal_map(text, "map.yaml");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("map.yaml:"), std::string::npos) << e.what();
  }
}

TEST(SignalMapConfig, UnusableMapsAreRefusedNamingWhy) {
  const std::string head = "name: m\nsample: {trigger: 0x10}\nframes:\n  - id: 0x10\n    signals:\n";
  const std::string i = "      - {field: i_d, start_bit: 0, length: 16, unit: A}\n"
                        "      - {field: i_q, start_bit: 16, length: 16, unit: A}\n";
  const std::string u = "      - {field: u_d, start_bit: 32, length: 8, unit: V}\n"
                        "      - {field: u_q, start_bit: 40, length: 8, unit: V}\n";
  const std::string w = "      - {field: omega_el, start_bit: 48, length: 16, signed: true, unit: rad/s}\n";
  EXPECT_NO_THROW((void)io::parse_signal_map(head + i + u + w, "map.yaml"));
  expect_refused(head + i + w, "does not give what the estimator needs: voltage");
  expect_refused(head + i + u, "speed (omega_el, erpm or speed_mech)");
  expect_refused(head + i + u + "      - {field: speed_mech, start_bit: 48, length: 16, unit: rpm}\n", "pole_pairs");
  expect_refused(head + i + u + "      - {field: omega_el, start_bit: 48, length: 16, unit: rpm}\n", "'rpm' for omega_el");
  expect_refused(head + i + u + "      - {field: omega, start_bit: 48, length: 16, unit: rad/s}\n", "unknown field 'omega'");
  expect_refused(head + i + u + "      - {field: omega_el, start_bit: 56, length: 16, unit: rad/s}\n", "outside the frame");
  expect_refused("name: m\nsample: {trigger: 0x11}\nframes:\n  - id: 0x10\n    signals:\n" + i + u + w, "trigger");
  expect_refused(head + i + u + w + "colour: blue\n", "colour");
}

}  // namespace
}  // namespace rpem::can
