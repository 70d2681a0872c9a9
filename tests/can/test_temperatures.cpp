// The temperature frame (ID 0x118, docs/can-protocol.md): a drive's winding and coolant sensors beside its
// phase samples, their readings going with the next sample delivered, and its bad input counted without
// touching the samples' stream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "rpem/can/e2e.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/core/clock.hpp"
#include "support_can.hpp"

namespace rpem::can {
namespace {

namespace p = protocol;
constexpr std::int64_t kPeriod_ns = 125'000;  // 8 kHz

/// 8 kHz samples over `duration_ns`, the winding warming 2 K/s from 60 °C and the coolant at 40 °C.
std::vector<core::DriveSample> warming(std::int64_t duration_ns) {
  std::mt19937_64 rng(11);
  std::vector<core::DriveSample> v;
  for (std::int64_t t = 0; t < duration_ns; t += kPeriod_ns) {
    core::DriveSample s = test::random_sample(rng, 5'000'000 + t);
    s.t_winding_C = 60.0 + 2.0 * core::to_seconds(t);
    s.t_coolant_C = 40.0;
    v.push_back(s);
  }
  return v;
}

std::vector<CanFrame> of_id(const std::vector<CanFrame>& frames, std::uint32_t id) {
  std::vector<CanFrame> v;
  for (const CanFrame& f : frames)
    if (f.id == id) v.push_back(f);
  return v;
}

/// A temperature frame built from the documented layout alone: bytes 3–4 and 5–6, 0.1 °C, little endian.
CanFrame temperature_frame(std::int16_t winding_raw, std::int16_t coolant_raw, std::uint8_t counter) {
  CanFrame f;
  f.id = 0x118;
  f.len = 8;
  f.data[3] = static_cast<std::uint8_t>(winding_raw & 0xFF);
  f.data[4] = static_cast<std::uint8_t>((winding_raw >> 8) & 0xFF);
  f.data[5] = static_cast<std::uint8_t>(coolant_raw & 0xFF);
  f.data[6] = static_cast<std::uint8_t>((coolant_raw >> 8) & 0xFF);
  e2e_protect(f, 0x5118, counter);  // Data ID 0x5100 + (0x118 − 0x100)
  return f;
}

/// The FD frame of one random sample at 1 ms of drive time, from a fresh encoder.
CanFrame one_sample(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  TelemetryEncoder enc(BusMode::kFd, 1);
  return test::encode_all(enc, {test::random_sample(rng, 1'000'000)}).at(0);
}

class TemperaturesOnEitherBus : public ::testing::TestWithParam<BusMode> {};

// 0.35 s of samples: frames at 0, 0.1, 0.2 and 0.3 s of drive time (protocol::kTemperaturePeriod_ns), each
// reading within half a step (0.05 K) of the sample that sent it, on as many decoded samples, every other
// sample NaN; and every sample still delivered.
TEST_P(TemperaturesOnEitherBus, EveryTenthOfASecondTheReadingsGoWithTheNextSample) {
  const std::vector<core::DriveSample> sent = warming(350'000'000);
  TelemetryEncoder enc(GetParam());
  const std::vector<CanFrame> frames = test::encode_all(enc, sent);
  const std::vector<CanFrame> temperature_frames = of_id(frames, p::kTemperatureId);
  ASSERT_EQ(temperature_frames.size(), 4U);
  for (const CanFrame& f : temperature_frames) {
    EXPECT_FALSE(f.fd);
    EXPECT_EQ(f.len, 8);
    EXPECT_EQ(f.data[7], 0);
  }
  TelemetryDecoder dec;
  const std::vector<core::DriveSample> got = test::decode_all(dec, frames);
  ASSERT_EQ(got.size(), sent.size());
  std::vector<std::size_t> carrying;
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(std::isnan(got[k].t_winding_C), std::isnan(got[k].t_coolant_C)) << k;
    if (!std::isnan(got[k].t_winding_C)) carrying.push_back(k);
  }
  ASSERT_EQ(carrying.size(), 4U);
  for (std::size_t j = 0; j < carrying.size(); ++j) {
    // Sent by the sample at j·0.1 s; delivered with the next sample to leave: FD holds up to three for a frame.
    const auto sender = static_cast<std::size_t>(j * 800);
    EXPECT_LE(std::max(carrying[j], sender) - std::min(carrying[j], sender), 2U) << j;
    EXPECT_NEAR(got[carrying[j]].t_winding_C, sent[sender].t_winding_C, 0.05 + 1e-9) << j;
    EXPECT_NEAR(got[carrying[j]].t_coolant_C, 40.0, 1e-9) << j;
  }
  EXPECT_EQ(dec.counters().unknown_id, 0U);
  EXPECT_EQ(dec.counters().gaps, 1U);  // the stream's first sample only
}

INSTANTIATE_TEST_SUITE_P(Bus, TemperaturesOnEitherBus, ::testing::Values(BusMode::kFd, BusMode::kClassic));

TEST(Temperatures, AFrameBuiltFromTheDocumentedLayoutDecodes) {
  TelemetryDecoder dec;
  std::array<core::DriveSample, 3> out;
  EXPECT_EQ(dec.decode(temperature_frame(812, -157, 0), 0, out), 0U);  // 81.2 °C, −15.7 °C
  ASSERT_EQ(dec.decode(one_sample(3), 0, out), 1U);
  EXPECT_NEAR(out[0].t_winding_C, 81.2, 1e-12);
  EXPECT_NEAR(out[0].t_coolant_C, -15.7, 1e-12);
}

// A drive without a coolant sensor sends the no-valid-value code: NaN, nothing counted; a saturated reading
// is counted out of range and dropped alone.
TEST(Temperatures, NoReadingIsNaNAndASaturatedOneIsCountedAndDropped) {
  std::mt19937_64 rng(5);
  TelemetryEncoder enc(BusMode::kFd, 1);
  const std::vector<CanFrame> samples =
      test::encode_all(enc, {test::random_sample(rng, 1'000'000), test::random_sample(rng, 1'125'000)});
  TelemetryDecoder dec;
  std::array<core::DriveSample, 3> out;
  EXPECT_EQ(dec.decode(temperature_frame(700, p::kInvalidI16, 0), 0, out), 0U);
  ASSERT_EQ(dec.decode(samples[0], 0, out), 1U);
  EXPECT_NEAR(out[0].t_winding_C, 70.0, 1e-12);
  EXPECT_TRUE(std::isnan(out[0].t_coolant_C));
  EXPECT_EQ(dec.counters().out_of_range + dec.counters().invalid_value, 0U);

  EXPECT_EQ(dec.decode(temperature_frame(p::kSaturatedI16, 350, 1), 0, out), 0U);
  ASSERT_EQ(dec.decode(samples[1], 0, out), 1U);
  EXPECT_TRUE(std::isnan(out[0].t_winding_C));
  EXPECT_NEAR(out[0].t_coolant_C, 35.0, 1e-12);
  EXPECT_EQ(dec.counters().out_of_range, 1U);
  EXPECT_FALSE(out[0].gap_before);  // a temperature is no sample: the samples' stream is whole
}

// A corrupted, repeated, reordered or wrongly framed temperature frame is counted by kind and its readings
// never delivered; none of them breaks the samples' stream (no gap).
TEST(Temperatures, BadTemperatureFramesAreCountedAndLeaveTheSamplesWhole) {
  std::mt19937_64 rng(9);
  std::vector<core::DriveSample> s;
  for (int k = 0; k < 6; ++k) s.push_back(test::random_sample(rng, 1'000'000 + k * kPeriod_ns));
  TelemetryEncoder enc(BusMode::kFd, 1);
  const std::vector<CanFrame> samples = test::encode_all(enc, s);
  CanFrame corrupted = temperature_frame(500, 300, 0);
  corrupted.data[4] ^= 0x01;
  CanFrame as_fd = temperature_frame(500, 300, 0);
  as_fd.fd = true;
  const CanFrame first = temperature_frame(510, 300, 5);
  const CanFrame behind = temperature_frame(520, 300, 4);

  TelemetryDecoder dec;
  std::vector<core::DriveSample> got;
  std::array<core::DriveSample, 3> out;
  auto sample = [&](int k) {
    ASSERT_EQ(dec.decode(samples[static_cast<std::size_t>(k)], 0, out), 1U);
    got.push_back(out[0]);
  };
  sample(0);
  EXPECT_EQ(dec.decode(corrupted, 0, out), 0U);
  sample(1);
  EXPECT_EQ(dec.decode(as_fd, 0, out), 0U);
  sample(2);
  EXPECT_EQ(dec.decode(first, 0, out), 0U);
  sample(3);
  EXPECT_EQ(dec.decode(first, 0, out), 0U);   // the same counter again
  EXPECT_EQ(dec.decode(behind, 0, out), 0U);  // a counter behind
  sample(4);
  sample(5);
  const DecoderCounters& c = dec.counters();
  EXPECT_EQ(c.crc_error, 1U);
  EXPECT_EQ(c.wrong_dlc, 1U);
  EXPECT_EQ(c.duplicated, 1U);
  EXPECT_EQ(c.reordered, 1U);
  EXPECT_EQ(c.gaps, 1U);  // the first sample's alone
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(std::isnan(got[k].t_winding_C), k != 3) << k;
    EXPECT_FALSE(k > 0 && got[k].gap_before) << k;
  }
  EXPECT_NEAR(got[3].t_winding_C, 51.0, 1e-12);
}

// resynchronize() forgets a reading not yet delivered: it belonged to the stream before the break.
TEST(Temperatures, AResynchronisedDecoderForgetsAPendingReading) {
  TelemetryDecoder dec;
  std::array<core::DriveSample, 3> out;
  EXPECT_EQ(dec.decode(temperature_frame(600, 300, 0), 0, out), 0U);
  dec.resynchronize();
  ASSERT_EQ(dec.decode(one_sample(13), 0, out), 1U);
  EXPECT_TRUE(std::isnan(out[0].t_winding_C));
  EXPECT_TRUE(std::isnan(out[0].t_coolant_C));
}

}  // namespace
}  // namespace rpem::can
