// Every class of bad input is counted by kind, dropped, and the next good sample carries a gap.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/can/e2e.hpp"
#include "rpem/can/protocol.hpp"
#include "support_can.hpp"

namespace rpem::can {
namespace {

namespace p = protocol;

struct Stream {
  std::vector<core::DriveSample> samples;
  std::vector<CanFrame> frames;
};

Stream stream(BusMode mode, int n, int per_frame = 3) {
  std::mt19937_64 rng(7);
  Stream s;
  for (int k = 0; k < n; ++k) s.samples.push_back(test::random_sample(rng, 10'000'000 + k * 125'000LL));
  TelemetryEncoder enc(mode, per_frame);
  s.frames = test::encode_all(enc, s.samples);
  return s;
}

/// Re-protects a frame after editing it (so only the intended defect remains).
void reprotect(CanFrame& f) { e2e_protect(f, p::data_id(f.id), e2e_counter(f)); }

TEST(BadInput, WrongDlcAndFrameType) {
  auto s = stream(BusMode::kFd, 6);
  TelemetryDecoder dec;
  CanFrame short_fd = s.frames[0];
  short_fd.len = 48;
  CanFrame classic_as_fd = s.frames[0];
  classic_as_fd.fd = false;
  auto c = stream(BusMode::kClassic, 1).frames[0];
  c.len = 7;
  std::array<core::DriveSample, 3> out;
  EXPECT_EQ(dec.decode(short_fd, 0, out), 0U);
  EXPECT_EQ(dec.decode(classic_as_fd, 0, out), 0U);
  EXPECT_EQ(dec.decode(c, 0, out), 0U);
  EXPECT_EQ(dec.counters().wrong_dlc, 3U);
}

TEST(BadInput, UnknownIdsAreCountedNotDecoded) {
  TelemetryDecoder dec;
  CanFrame f;
  f.id = 0x7FF;
  f.len = 8;
  std::array<core::DriveSample, 3> out;
  EXPECT_EQ(dec.decode(f, 0, out), 0U);
  EXPECT_EQ(dec.counters().unknown_id, 1U);
}

TEST(BadInput, CrcMismatchDropsTheFrameAndMarksAGap) {
  auto s = stream(BusMode::kFd, 9);
  s.frames[1].data[20] ^= 0x04;
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, s.frames);
  EXPECT_EQ(out.size(), 6U);
  EXPECT_EQ(dec.counters().crc_error, 1U);
  EXPECT_TRUE(out[3].gap_before);
  EXPECT_EQ(out[3].t_ns, s.samples[6].t_ns);
}

TEST(BadInput, LostDuplicatedAndReorderedFrames) {
  auto s = stream(BusMode::kFd, 30);  // 10 frames
  std::vector<CanFrame> f = s.frames;
  std::vector<CanFrame> received = {f[0], f[1], f[1], f[3], f[2], f[4], f[7], f[8], f[9]};
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, received);
  const auto& c = dec.counters();
  EXPECT_EQ(c.duplicated, 1U);        // f[1] twice
  EXPECT_EQ(c.reordered, 1U);         // f[2] after f[3]
  EXPECT_EQ(c.frames_lost, 1U + 2U);  // f[2] (jump 1→3) and f[5], f[6]
  EXPECT_EQ(out.size(), 3U * 7U);
  // Gaps where frames went missing, nowhere else.
  int gaps = 0;
  for (const auto& x : out) gaps += x.gap_before ? 1 : 0;
  EXPECT_EQ(gaps, 3);  // the first sample, after the jump to f[3], after the jump to f[7]
  EXPECT_EQ(c.gaps, 3U);
}

TEST(BadInput, StaleTimestampsAreDropped) {
  auto s = stream(BusMode::kFd, 9);
  // A frame with a correct counter but a drive time that does not advance (frozen telemetry).
  CanFrame frozen = s.frames[2];
  p::put_u32(frozen, 4, p::get_u32(s.frames[1], 4));
  reprotect(frozen);
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, {s.frames[0], s.frames[1], frozen});
  EXPECT_EQ(out.size(), 6U);
  EXPECT_EQ(dec.counters().stale, 3U);
}

TEST(BadInput, OutOfRangeAndInvalidValues) {
  std::mt19937_64 rng(9);
  std::vector<core::DriveSample> in;
  for (int k = 0; k < 6; ++k) in.push_back(test::random_sample(rng, 1'000'000 + k * 125'000LL));
  in[1].i_A[2] = 40.0;                // beyond ±32.767 A: saturated code
  in[3].u_V[0] = std::nan("");        // no valid value
  in[4].theta_el_rad = std::nan("");  // no valid angle: the whole frame is flagged
  TelemetryEncoder enc(BusMode::kFd, 1);
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, test::encode_all(enc, in));
  EXPECT_EQ(out.size(), 3U);
  EXPECT_EQ(dec.counters().out_of_range, 1U);
  EXPECT_EQ(dec.counters().invalid_value, 2U);
  EXPECT_TRUE(out[1].gap_before);  // sample 2, after the saturated one
  EXPECT_TRUE(out[2].gap_before);  // sample 5
  for (const auto& x : out) EXPECT_TRUE(x.i_A.allFinite() && x.u_V.allFinite() && std::isfinite(x.theta_el_rad));
}

TEST(BadInput, BadVersionSampleCountAndPeriod) {
  auto s = stream(BusMode::kFd, 12);
  CanFrame v2 = s.frames[0];
  v2.data[3] = 0x23;
  reprotect(v2);
  CanFrame four = s.frames[1];
  four.data[3] = 0x14;
  reprotect(four);
  CanFrame zero_period = s.frames[2];
  p::put_u16(zero_period, 8, 0);
  reprotect(zero_period);
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, {v2, four, zero_period, s.frames[3]});
  EXPECT_EQ(dec.counters().bad_version, 1U);
  EXPECT_EQ(dec.counters().wrong_dlc, 1U);
  EXPECT_EQ(dec.counters().invalid_value, 1U);
  ASSERT_EQ(out.size(), 3U);
  EXPECT_TRUE(out[0].gap_before);
}

TEST(BadInput, ClassicSampleWithAMissingPartIsDropped) {
  auto s = stream(BusMode::kClassic, 4);
  std::vector<CanFrame> f = s.frames;
  f.erase(f.begin() + 7);  // the third frame (0x112) of sample 1
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, f);
  EXPECT_EQ(out.size(), 3U);
  EXPECT_EQ(dec.counters().incomplete, 1U);  // parts may come in any order; a missing one shows at the next start
  EXPECT_EQ(dec.counters().reordered, 0U);
  EXPECT_TRUE(out[1].gap_before);
  EXPECT_EQ(out[1].t_ns, s.samples[2].t_ns);
}

TEST(BadInput, ClassicSampleCutShortIsIncomplete) {
  auto s = stream(BusMode::kClassic, 3);
  std::vector<CanFrame> f = s.frames;
  f.erase(f.begin() + 9);  // the last frame (0x114) of sample 1
  TelemetryDecoder dec;
  const auto out = test::decode_all(dec, f);
  EXPECT_EQ(out.size(), 2U);
  EXPECT_EQ(dec.counters().incomplete, 1U);
  EXPECT_TRUE(out[1].gap_before);
}

TEST(BadInput, ResynchronizeStartsANewStreamWithAGap) {
  auto s = stream(BusMode::kFd, 9);
  TelemetryDecoder dec;
  auto out = test::decode_all(dec, {s.frames[0], s.frames[1]});
  dec.resynchronize();
  out = test::decode_all(dec, {s.frames[2]});
  ASSERT_EQ(out.size(), 3U);
  EXPECT_TRUE(out[0].gap_before);
}

}  // namespace
}  // namespace rpem::can
