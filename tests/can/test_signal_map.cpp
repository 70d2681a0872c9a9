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

// The sample's i_d, i_q [A] and u_d, u_q [V]: exact (every value here is a short binary fraction).
void expect_dq(const core::AveragedSample& s, double i_d, double i_q, double u_d, double u_q) {
  EXPECT_EQ(s.i_dq_A[0], i_d);
  EXPECT_EQ(s.i_dq_A[1], i_q);
  EXPECT_EQ(s.u_dq_V[0], u_d);
  EXPECT_EQ(s.u_dq_V[1], u_q);
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
  // TxPDO1: 0x606C INT32 in 0.0001 rpm: 1500 rpm = 15 000 000 = 0x00E4E1C0.
  const CanFrame speed = frame(0x181, {0xC0, 0xE1, 0xE4, 0x00});
  // TxPDO2: 0x3242:05 Id, :04 Iq as REAL32 (IEEE 754 binary32, little endian), worked by hand:
  //   −2.5 = −1.01b·2^1: sign 1, exponent 127+1 = 0x80, fraction .01b → 0xC0200000 → 00 00 20 C0
  //   12.5 = 1.1001b·2^3: sign 0, exponent 130 = 0x82, fraction .1001b → 0x41480000 → 00 00 48 41
  const CanFrame currents = frame(0x281, {0x00, 0x00, 0x20, 0xC0, 0x00, 0x00, 0x48, 0x41});
  // TxPDO3: 0x3242:10 Ud, :0F Uq: −20 = −1.01b·2^4 → 0xC1A00000; 150.5 = 1.00101101b·2^7 (exponent 134 =
  // 0x86) → 0x43168000.
  const CanFrame voltages = frame(0x381, {0x00, 0x00, 0xA0, 0xC1, 0x00, 0x80, 0x16, 0x43});
  // TxPDO4 (the trigger): 0x6079 UINT32 560 000 mV = 0x00088B80 → 80 8B 08 00; 0x32C1:06 REAL32 72.5 °C =
  // 1001000.1b = 1.0010001b·2^6 (exponent 127+6 = 133 = 0x85) → 0 10000101 0010001 0… = 0x42910000 → 00 00 91 42.
  const CanFrame dc_link = frame(0x481, {0x80, 0x8B, 0x08, 0x00, 0x00, 0x00, 0x91, 0x42});

  EXPECT_FALSE(dec.decode(speed, 1000, s));
  EXPECT_FALSE(dec.decode(currents, 1000, s));
  EXPECT_FALSE(dec.decode(voltages, 1000, s));
  EXPECT_FALSE(dec.decode(frame(0x701, {0x05}), 1000, s));  // heartbeat: not mapped, ignored
  ASSERT_TRUE(dec.decode(dc_link, 2000, s));
  EXPECT_DOUBLE_EQ(s.omega_el_rad_s, 1500.0 * 2.0 * std::numbers::pi / 60.0 * 4);
  expect_dq(s, -2.5, 12.5, -20.0, 150.5);
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
  EXPECT_FALSE(dec.decode(speed, 3000, s));
  EXPECT_FALSE(dec.decode(currents, 3000, s));
  EXPECT_FALSE(dec.decode(dc_link, 3000, s));
  EXPECT_EQ(dec.counters().incomplete, 1U);
  EXPECT_FALSE(dec.decode(frame(0x281, {0x00, 0x00, 0x20}), 4000, s));  // too short
  EXPECT_EQ(dec.counters().wrong_length, 1U);
  // An Iq of NaN (quiet NaN 0x7FC00000): the PDO is dropped and counted, the SYNC cycle is incomplete.
  CanFrame nan_iq = currents;
  nan_iq.data[6] = 0xC0;
  nan_iq.data[7] = 0x7F;
  EXPECT_FALSE(dec.decode(speed, 5000, s));
  EXPECT_FALSE(dec.decode(nan_iq, 5000, s));
  EXPECT_FALSE(dec.decode(voltages, 5000, s));
  EXPECT_FALSE(dec.decode(dc_link, 5000, s));
  EXPECT_EQ(dec.counters().non_finite, 1U);
  EXPECT_EQ(dec.counters().incomplete, 2U);
  EXPECT_EQ(dec.counters().samples, 1U);
}

// IEEE 754 signals (DBC SIG_VALTYPE_ 1 and 2) against bytes worked by hand; Python's struct.pack('<f'/'>f'/
// '<d'/'>d', v) gives the same bytes.
TEST(SignalMapFloats, Binary32AndBinary64InBothByteOrdersWithScaleAndOffset) {
  const auto spec = [](int start, int length, bool big, ValueType t, double scale = 1.0, double offset = 0.0) {
    SignalSpec s;
    s.start_bit = start;
    s.length = length;
    s.big_endian = big;
    s.value_type = t;
    s.scale = scale;
    s.offset = offset;
    return s;
  };
  using V = ValueType;
  // binary32 little endian in bytes 0..3 (−2.5 = 0xC0200000), big endian in bytes 4..7 (150.5 = 0x43168000;
  // DBC start bit of the MSB = bit 7 of byte 4 = 39).
  const CanFrame f32 = frame(1, {0x00, 0x00, 0x20, 0xC0, 0x43, 0x16, 0x80, 0x00});
  EXPECT_EQ(physical_value(f32, spec(0, 32, false, V::kFloat32)), -2.5);
  EXPECT_EQ(physical_value(f32, spec(39, 32, true, V::kFloat32)), 150.5);
  // Scale and offset apply as to integers: 150.5·2 − 1.
  EXPECT_EQ(physical_value(f32, spec(39, 32, true, V::kFloat32, 2.0, -1.0)), 300.0);
  // binary64: 230.25 = 1.110011001b·2^7, exponent 1023+7 = 0x406, fraction 0xCC8000… → 0x406CC80000000000.
  EXPECT_EQ(physical_value(frame(1, {0, 0, 0, 0, 0, 0xC8, 0x6C, 0x40}), spec(0, 64, false, V::kFloat64)), 230.25);
  EXPECT_EQ(physical_value(frame(1, {0x40, 0x6C, 0xC8, 0, 0, 0, 0, 0}), spec(7, 64, true, V::kFloat64)), 230.25);
  // −0.1 (not exact in binary: the nearest double, 0xBFB999999999999A).
  EXPECT_EQ(physical_value(frame(1, {0x9A, 0x99, 0x99, 0x99, 0x99, 0x99, 0xB9, 0xBF}), spec(0, 64, false, V::kFloat64)),
            -0.1);
  // In a CAN FD frame: binary32 big endian at byte 12 (MSB at DBC bit 12·8+7 = 103), 12.5 = 0x41480000.
  CanFrame fd;
  fd.len = 16;
  fd.fd = true;
  fd.data[12] = 0x41;
  fd.data[13] = 0x48;
  EXPECT_EQ(physical_value(fd, spec(103, 32, true, V::kFloat32)), 12.5);
  // Edge values: the smallest subnormal (0x00000001 = 2^-149) is finite and read exactly; −0 (0x80000000)
  // is zero (−0·1 + 0 = +0 in IEEE arithmetic: the offset's addition drops the sign of a zero).
  EXPECT_EQ(physical_value(frame(1, {0x01, 0, 0, 0}), spec(0, 32, false, V::kFloat32)), std::ldexp(1.0, -149));
  EXPECT_EQ(physical_value(frame(1, {0, 0, 0, 0x80}), spec(0, 32, false, V::kFloat32)), 0.0);
  // NaN (0x7FC00000), +∞ (0x7F800000), −∞ (0xFF800000); and a finite double that overflows its scale.
  EXPECT_TRUE(std::isnan(physical_value(frame(1, {0, 0, 0xC0, 0x7F}), spec(0, 32, false, V::kFloat32))));
  EXPECT_EQ(physical_value(frame(1, {0, 0, 0x80, 0x7F}), spec(0, 32, false, V::kFloat32)), HUGE_VAL);
  EXPECT_EQ(physical_value(frame(1, {0, 0, 0x80, 0xFF}), spec(0, 32, false, V::kFloat32)), -HUGE_VAL);
  // 1e300 = 0x7E37E43C8800759C; ·1e12 is beyond the largest double.
  EXPECT_TRUE(std::isinf(
      physical_value(frame(1, {0x9C, 0x75, 0x00, 0x88, 0x3C, 0xE4, 0x37, 0x7E}), spec(0, 64, false, V::kFloat64, 1e12))));
}

TEST(SignalMapFloats, NanAndInfinityAreCountedAndNeverDelivered) {
  const std::string text =
      "name: floats\nsample: {trigger: 0x12, averaged: true}\nframes:\n"
      "  - {id: 0x10, signals: [{field: i_d, start_bit: 0, length: 32, value_type: float, unit: A},\n"
      "                         {field: i_q, start_bit: 32, length: 32, value_type: float, unit: A}]}\n"
      "  - {id: 0x11, signals: [{field: u_d, start_bit: 7, length: 32, byte_order: big_endian, value_type: float, unit: V},\n"
      "                         {field: u_q, start_bit: 39, length: 32, byte_order: big_endian, value_type: float, unit: V}]}\n"
      "  - {id: 0x12, signals: [{field: omega_el, start_bit: 7, length: 64, byte_order: big_endian, value_type: double, unit: rad/s}]}\n"
      "  - {id: 0x13, signals: [{field: u_dc, start_bit: 0, length: 64, value_type: double, unit: V}]}\n";
  SignalMapDecoder dec(io::parse_signal_map(text, "floats.yaml"));
  // i_d −2.5, i_q 12.5 (LE binary32); u_d −20, u_q 150.5 (BE binary32); ω 230.25 (BE binary64); u_dc 230.25 (LE binary64).
  const CanFrame i = frame(0x10, {0x00, 0x00, 0x20, 0xC0, 0x00, 0x00, 0x48, 0x41});
  const CanFrame u = frame(0x11, {0xC1, 0xA0, 0x00, 0x00, 0x43, 0x16, 0x80, 0x00});
  const CanFrame w = frame(0x12, {0x40, 0x6C, 0xC8, 0, 0, 0, 0, 0});
  const CanFrame dc = frame(0x13, {0, 0, 0, 0, 0, 0xC8, 0x6C, 0x40});
  core::AveragedSample s;
  auto cycle = [&](const CanFrame& fi, const CanFrame& fu, const CanFrame& fw, std::int64_t t) {
    EXPECT_FALSE(dec.decode(fi, t, s));
    EXPECT_FALSE(dec.decode(fu, t, s));
    return dec.decode(fw, t, s);
  };
  EXPECT_FALSE(dec.decode(dc, 0, s));
  ASSERT_TRUE(cycle(i, u, w, 1000));
  expect_dq(s, -2.5, 12.5, -20.0, 150.5);
  EXPECT_EQ(s.omega_el_rad_s, 230.25);
  EXPECT_EQ(s.u_dc_V, 230.25);
  ASSERT_TRUE(cycle(i, u, w, 2000));
  EXPECT_FALSE(s.gap_before);

  // i_q NaN: the current frame is dropped (its finite i_d too), the sample incomplete, the chain broken.
  CanFrame bad_i = i;
  bad_i.data[6] = 0xC0;
  bad_i.data[7] = 0x7F;
  EXPECT_FALSE(cycle(bad_i, u, w, 3000));
  EXPECT_EQ(dec.counters().non_finite, 1U);
  EXPECT_EQ(dec.counters().incomplete, 1U);
  ASSERT_TRUE(cycle(i, u, w, 4000));
  EXPECT_TRUE(s.gap_before);
  EXPECT_EQ(s.t_start_ns, 4000);

  // u_dc +∞ (an optional quantity): dropped and counted; the sample goes out without it, never with ∞.
  EXPECT_FALSE(dec.decode(frame(0x13, {0, 0, 0, 0, 0, 0, 0xF0, 0x7F}), 4500, s));
  EXPECT_EQ(dec.counters().non_finite, 2U);
  ASSERT_TRUE(cycle(i, u, w, 5000));
  EXPECT_TRUE(std::isnan(s.u_dc_V));  // not reported this cycle
  EXPECT_FALSE(s.gap_before);

  // The trigger's speed −∞: no sample, and the next one starts a new chain.
  EXPECT_FALSE(cycle(i, u, frame(0x12, {0xFF, 0xF0, 0, 0, 0, 0, 0, 0}), 6000));
  EXPECT_EQ(dec.counters().non_finite, 3U);
  ASSERT_TRUE(cycle(i, u, w, 7000));
  EXPECT_TRUE(s.gap_before);
  EXPECT_EQ(s.t_start_ns, 7000);
  EXPECT_EQ(dec.counters().samples, 5U);  // 1000, 2000, 4000, 5000, 7000
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
  const std::vector<core::AveragedSample> got = test::decode_all(dec, frames, 0);
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
    EXPECT_EQ(got[k].t_ns, r.t_ns);  // the drive's T_low (t_sample), not the receive time (0 here)
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
  const std::string i =
      "      - {field: i_d, start_bit: 0, length: 16, unit: A}\n"
      "      - {field: i_q, start_bit: 16, length: 16, unit: A}\n";
  const std::string u =
      "      - {field: u_d, start_bit: 32, length: 8, unit: V}\n"
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

// A map whose frame 0x10 carries a sample's currents, voltages and speed, and whose frame 0x11 carries one temperature
// `field` as SAE J1939 scales one (0.03125 °C/bit, offset −273 °C; all ones, 65535, its "not available").
std::string j1939_temperature_map(const std::string& field) {
  return "name: j1939ish\nsample: {trigger: 0x10}\nframes:\n"
         "  - {id: 0x10, signals: [\n"
         "      {field: i_d, start_bit: 0, length: 16, signed: true, scale: 0.01, unit: A},\n"
         "      {field: i_q, start_bit: 16, length: 16, signed: true, scale: 0.01, unit: A},\n"
         "      {field: u_d, start_bit: 32, length: 8, signed: true, scale: 0.1, unit: V},\n"
         "      {field: u_q, start_bit: 40, length: 8, signed: true, scale: 0.1, unit: V},\n"
         "      {field: erpm, start_bit: 48, length: 16, signed: true, unit: rpm}]}\n"
         "  - {id: 0x11, length: 2, signals: [\n"
         "      {field: " +
         field + ", start_bit: 0, length: 16, scale: 0.03125, offset: -273, no_reading: 65535, unit: degC}]}\n";
}
/// j1939_temperature_map's frame 0x10: i = (1, 2) A, u = (1, 2) V, 1000 erpm.
CanFrame j1939_values() { return frame(0x10, {0x64, 0x00, 0xC8, 0x00, 0x0A, 0x14, 0xE8, 0x03}); }

// A temperature sensor's "no reading" (SAE J1939's all-ones "not available" for a 16-bit unsigned parameter): the
// field is not received in that frame, the sample is one as ever, and it is counted; a reading again is used again.
TEST(SignalMapNoReading, ATemperaturesNoReadingValueLeavesTheSampleWithoutIt) {
  const std::string text = j1939_temperature_map("T_winding");
  SignalMapDecoder dec(io::parse_signal_map(text, "j1939ish.yaml"));
  const CanFrame values = j1939_values();
  core::AveragedSample s;
  EXPECT_FALSE(dec.decode(frame(0x11, {0xFF, 0xFF}), 1'000'000, s));
  ASSERT_TRUE(dec.decode(values, 1'000'000, s));
  EXPECT_TRUE(std::isnan(s.t_winding_C));
  EXPECT_DOUBLE_EQ(s.i_dq_A[1], 2.0);
  EXPECT_DOUBLE_EQ(s.u_dq_V[1], 2.0);
  EXPECT_EQ(dec.counters().no_reading, 1U);
  EXPECT_EQ(dec.counters().samples, 1U);
  EXPECT_FALSE(dec.decode(frame(0x11, {0x80, 0x25}), 2'000'000, s));  // 9600 · 0.03125 − 273 = 27 °C
  ASSERT_TRUE(dec.decode(values, 2'000'000, s));
  EXPECT_DOUBLE_EQ(s.t_winding_C, 27.0);
  EXPECT_EQ(dec.counters().no_reading, 1U);
  // Refused at load: on a field other than a temperature, on a float, and a value its bits cannot hold.
  const std::string head = text.substr(0, text.find("  - {id: 0x11"));
  expect_refused(head + "  - {id: 0x11, signals: [{field: u_dc, start_bit: 0, length: 16, no_reading: 65535, unit: V}]}\n",
                 "no_reading is a temperature sensor's");
  expect_refused(head +
                     "  - {id: 0x11, signals: [{field: T_winding, start_bit: 0, length: 32, value_type: float, "
                     "no_reading: 0, unit: degC}]}\n",
                 "no_reading is an integer signal's raw value");
  expect_refused(
      head + "  - {id: 0x11, signals: [{field: T_winding, start_bit: 0, length: 16, no_reading: 65536, unit: degC}]}\n",
      "no_reading 65536 is not a raw value of 16 unsigned bits");
  expect_refused(head +
                     "  - {id: 0x11, signals: [{field: T_winding, start_bit: 0, length: 8, signed: true, no_reading: -129, "
                     "unit: degC}]}\n",
                 "no_reading -129 is not a raw value of 8 signed bits");
}

// The coolant's sensor (T_coolant: the thermal network's boundary, docs/thermal.md) is read as any temperature is:
// its value in the sample's t_coolant_C, its no-reading value and a cycle without its frame none.
TEST(SignalMapNoReading, TheCoolantIsATemperatureWithItsNoReadingValue) {
  SignalMapDecoder dec(io::parse_signal_map(j1939_temperature_map("T_coolant"), "j1939ish.yaml"));
  core::AveragedSample s;
  EXPECT_FALSE(dec.decode(frame(0x11, {0x40, 0x24}), 1'000'000, s));  // 9280 · 0.03125 − 273 = 17 °C
  ASSERT_TRUE(dec.decode(j1939_values(), 1'000'000, s));
  EXPECT_DOUBLE_EQ(s.t_coolant_C, 17.0);
  EXPECT_TRUE(std::isnan(s.t_winding_C));
  EXPECT_FALSE(dec.decode(frame(0x11, {0xFF, 0xFF}), 2'000'000, s));
  ASSERT_TRUE(dec.decode(j1939_values(), 2'000'000, s));
  EXPECT_TRUE(std::isnan(s.t_coolant_C));
  EXPECT_EQ(dec.counters().no_reading, 1U);
  ASSERT_TRUE(dec.decode(j1939_values(), 3'000'000, s));  // no coolant frame in this cycle
  EXPECT_TRUE(std::isnan(s.t_coolant_C));
  EXPECT_EQ(dec.counters().samples, 3U);
}

TEST(SignalMapConfig, FloatSignalsMustBeWholeByteAlignedIeeeValues) {
  const std::string head = "name: m\nsample: {trigger: 0x10}\nframes:\n  - id: 0x10\n    signals:\n";
  const std::string u =
      "      - {field: u_d, start_bit: 32, length: 8, unit: V}\n"
      "      - {field: u_q, start_bit: 40, length: 8, unit: V}\n"
      "      - {field: omega_el, start_bit: 48, length: 16, signed: true, unit: rad/s}\n";
  const auto i = [](const std::string& i_d) { return i_d + "      - {field: i_q, start_bit: 16, length: 16, unit: A}\n"; };
  // Accepted: binary32 from bit 0 (LE), and big endian with its MSB at bit 7 of a byte.
  EXPECT_NO_THROW((void)io::parse_signal_map(
      head +
          "      - {field: i_d, start_bit: 0, length: 32, value_type: float, unit: A}\n"
          "      - {field: i_q, start_bit: 39, length: 32, byte_order: big_endian, value_type: float, unit: A}\n"
          "  - id: 0x11\n    signals:\n"
          "      - {field: u_d, start_bit: 0, length: 64, value_type: double, unit: V}\n"
          "  - id: 0x12\n    signals:\n"
          "      - {field: u_q, start_bit: 7, length: 64, byte_order: big_endian, value_type: double, unit: V}\n"
          "  - id: 0x13\n    signals:\n"
          "      - {field: omega_el, start_bit: 0, length: 32, value_type: float, scale: 6.283185307179586, unit: rad/s}\n",
      "map.yaml"));
  expect_refused(head + i("      - {field: i_d, start_bit: 0, length: 16, value_type: float, unit: A}\n") + u,
                 "binary32 (float) is 32 bits, not 16");
  expect_refused(head +
                     "      - {field: i_d, start_bit: 0, length: 32, value_type: double, unit: A}\n"
                     "      - {field: i_q, start_bit: 32, length: 32, value_type: double, unit: A}\n" +
                     "  - id: 0x11\n    signals:\n" + u,
                 "binary64 (double) is 64 bits, not 32");
  expect_refused(head + "      - {field: i_d, start_bit: 4, length: 32, value_type: float, unit: A}\n" + u,
                 "must start on a byte boundary");
  expect_refused(
      head + "      - {field: i_d, start_bit: 0, length: 32, byte_order: big_endian, value_type: float, unit: A}\n" + u,
      "must start on a byte boundary");
  expect_refused(head + i("      - {field: i_d, start_bit: 0, length: 32, value_type: float, signed: true, unit: A}\n") + u,
                 "carries its own sign");
  expect_refused(head + i("      - {field: i_d, start_bit: 0, length: 16, value_type: half, unit: A}\n") + u, "value_type");
}

}  // namespace
}  // namespace rpem::can
