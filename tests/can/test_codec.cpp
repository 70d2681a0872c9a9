// Encoder and decoder round trip: every value comes back within half its resolution; times exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/can/protocol.hpp"
#include "support/seed.hpp"
#include "support_can.hpp"

namespace rpem::can {
namespace {

namespace p = protocol;

void expect_within_resolution(const core::DriveSample& in, const core::DriveSample& out) {
  EXPECT_EQ(out.t_ns, in.t_ns / 1000 * 1000);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(out.i_A[k], in.i_A[k], p::kCurrentLsb_A / 2 + 1e-12);
    EXPECT_NEAR(out.u_V[k], in.u_V[k], p::kVoltageLsb_V / 2 + 1e-12);
  }
  EXPECT_NEAR(std::remainder(out.theta_el_rad - in.theta_el_rad, 2 * core::kPi), 0.0, p::kAngleLsb_rad / 2 + 1e-12);
  EXPECT_NEAR(out.omega_el_rad_s, in.omega_el_rad_s, p::kSpeedLsb_rad_s / 2 + 1e-12);
  EXPECT_EQ(out.current_frame, core::Frame::kAbc);
}

class RoundTrip : public ::testing::TestWithParam<std::pair<BusMode, int>> {};

TEST_P(RoundTrip, ValuesWithinHalfAnLsbAndNoGaps) {
  std::mt19937_64 rng(test::test_seed(100 + GetParam().second));
  std::vector<core::DriveSample> in;
  for (int k = 0; k < 3000; ++k) in.push_back(test::random_sample(rng, 1'000'000'000LL + k * 125'000LL));
  TelemetryEncoder enc(GetParam().first, GetParam().second);
  TelemetryDecoder dec;
  const auto frames = test::encode_all(enc, in);
  const std::size_t expected_frames =
      GetParam().first == BusMode::kClassic ? in.size() * 5 : (in.size() + GetParam().second - 1) / GetParam().second;
  EXPECT_EQ(frames.size(), expected_frames);
  const auto out = test::decode_all(dec, frames);
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t k = 0; k < in.size(); ++k) {
    expect_within_resolution(in[k], out[k]);
    EXPECT_EQ(out[k].gap_before, k == 0);
    EXPECT_NEAR(out[k].u_dc_V, GetParam().first == BusMode::kClassic ? in[k].u_dc_V : in[k - k % GetParam().second].u_dc_V,
                p::kDcLinkLsb_V / 2 + 1e-12);
  }
  const DecoderCounters& c = dec.counters();
  EXPECT_EQ(c.samples, in.size());
  EXPECT_EQ(c.crc_error + c.frames_lost + c.duplicated + c.reordered + c.stale + c.out_of_range + c.invalid_value +
                c.wrong_dlc + c.unknown_id + c.incomplete,
            0U);
}

INSTANTIATE_TEST_SUITE_P(Modes, RoundTrip,
                         ::testing::Values(std::pair{BusMode::kFd, 3}, std::pair{BusMode::kFd, 2},
                                           std::pair{BusMode::kFd, 1}, std::pair{BusMode::kClassic, 1}));

TEST(Codec, FdFrameLayoutMatchesTheDocumentedOffsets) {
  core::DriveSample s;
  s.t_ns = 0x12345678LL * 1000;
  s.u_dc_V = 220.0;
  s.i_A = {1.0, -2.0, 1.0};
  s.u_V = {10.0, -5.0, -5.0};
  s.theta_el_rad = core::kPi / 2;
  s.omega_el_rad_s = 100.0;
  TelemetryEncoder enc(BusMode::kFd, 1);
  std::array<CanFrame, TelemetryEncoder::kMaxFramesPerAdd> buf;
  ASSERT_EQ(enc.add(s, p::status::kPwmEnabled, buf), 1U);
  const CanFrame& f = buf[0];
  EXPECT_EQ(f.id, 0x100U);
  EXPECT_EQ(f.len, 64);
  EXPECT_EQ(f.data[3], 0x11);  // version 1, one sample
  EXPECT_EQ(p::get_u32(f, 4), 0x12345678U);
  EXPECT_EQ(p::get_u16(f, 10), 11000);  // 220 V / 0.02 V
  EXPECT_EQ(f.data[12], p::status::kPwmEnabled);
  EXPECT_EQ(p::get_i16(f, 13), 1000);
  EXPECT_EQ(p::get_i16(f, 15), -2000);
  EXPECT_EQ(p::get_i16(f, 19), 500);
  EXPECT_EQ(p::get_u16(f, 25), 16384);  // π/2
  EXPECT_EQ(p::get_i16(f, 27), 2000);   // 100 rad/s / 0.05
}

TEST(Codec, RotorFrameSamplesAreSentAsPhases) {
  core::DriveSample s;
  s.t_ns = 1000;
  s.u_dc_V = 100;
  s.theta_el_rad = 0.7;
  s.current_frame = core::Frame::kDq;
  s.i_A = {-1.0, 3.0, 0.0};
  s.voltage_frame = core::Frame::kDq;
  s.u_V = {-20.0, 80.0, 0.0};
  TelemetryEncoder enc(BusMode::kFd, 1);
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, test::encode_all(enc, {s}));
  ASSERT_EQ(out.size(), 1U);
  const core::Rotation r = core::Rotation::of(out[0].theta_el_rad);
  EXPECT_LT((core::park(core::clarke(out[0].i_A), r) - core::Vec2(-1.0, 3.0)).norm(), 3e-3);
}

TEST(Codec, DriveTimeUnwrapsAcrossTheThirtyTwoBitMicrosecondCounter) {
  std::mt19937_64 rng(1);
  std::vector<core::DriveSample> in;
  const std::int64_t start_us = (1LL << 32) - 1000;
  for (int k = 0; k < 60; ++k) in.push_back(test::random_sample(rng, (start_us + k * 125) * 1000));
  TelemetryEncoder enc(BusMode::kFd, 3);
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, test::encode_all(enc, in));
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t k = 1; k < out.size(); ++k) EXPECT_EQ(out[k].t_ns - out[k - 1].t_ns, 125'000) << k;
}

TEST(Codec, ClassicTimeUnwrapsAcrossItsTwentyFourBits) {
  std::mt19937_64 rng(2);
  std::vector<core::DriveSample> in;
  for (int k = 0; k < 40; ++k) in.push_back(test::random_sample(rng, ((1LL << 24) - 10'000 + k * 1000) * 1000));
  TelemetryEncoder enc(BusMode::kClassic);
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, test::encode_all(enc, in));
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t k = 1; k < out.size(); ++k) EXPECT_EQ(out[k].t_ns - out[k - 1].t_ns, 1'000'000) << k;
}

TEST(Codec, AnOffGridSampleClosesTheFdFrame) {
  std::mt19937_64 rng(3);
  std::vector<core::DriveSample> in = {test::random_sample(rng, 0), test::random_sample(rng, 125'000),
                                       test::random_sample(rng, 300'000), test::random_sample(rng, 425'000)};
  TelemetryEncoder enc(BusMode::kFd, 3);
  TelemetryDecoder dec;
  const auto frames = test::encode_all(enc, in);
  EXPECT_EQ(frames.size(), 2U);
  const auto out = test::decode_all(dec, frames);
  ASSERT_EQ(out.size(), 4U);
  EXPECT_EQ(out[2].t_ns, 300'000);
  EXPECT_EQ(out[3].t_ns, 425'000);
}

}  // namespace
}  // namespace rpem::can
