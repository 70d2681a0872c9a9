// A signal map's t_sample: the samples' times are the drive's, whatever the receive times (can/sample_clock.hpp).
// Every expected time is worked by hand from the counts in the frames; the receive times are chosen to be
// wrong (a burst, a late frame, a silence longer than the counter's wrap).
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <random>

#include "rpem/can/decoder.hpp"
#include "rpem/can/encoder.hpp"
#include "rpem/can/signal_map.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/signal_map_config.hpp"
#include "support/temp_file.hpp"
#include "support_can.hpp"

namespace rpem::can {
namespace {

// The trigger frame 0x10: i_d, i_q, u_d, u_q, omega_el in bytes 0–4 (the rest of the map follows).
const std::string kQuantities =
    "name: clock\nsample: {trigger: 0x10}\nframes:\n  - id: 0x10\n    signals:\n"
    "      - {field: i_d, start_bit: 0, length: 8, unit: A}\n"
    "      - {field: i_q, start_bit: 8, length: 8, unit: A}\n"
    "      - {field: u_d, start_bit: 16, length: 8, unit: V}\n"
    "      - {field: u_q, start_bit: 24, length: 8, unit: V}\n"
    "      - {field: omega_el, start_bit: 32, length: 8, unit: rad/s}\n";

// The drive's clock in byte 5 of the trigger: an 8-bit count of milliseconds, wrapping every 256 ms.
SignalMap millisecond_map(const std::string& clock = "length: 8, scale: 1.0e-3") {
  return io::parse_signal_map(kQuantities + "      - {field: t_sample, start_bit: 40, " + clock + ", unit: s}\n", "ms.yaml");
}

CanFrame at_count(std::uint8_t ms) {
  CanFrame f;
  f.id = 0x10;
  f.len = 8;
  f.data[0] = 1;
  f.data[5] = ms;
  return f;
}

constexpr std::int64_t kMs = 1'000'000;

TEST(SampleClock, ABurstOfLateFramesKeepsTheDrivesSteps) {
  // rpem's classic frames through config/signal-maps/rpem-native-classic.yaml, every frame received at the
  // same instant (a starved receiver reading its socket once): the times are the drive's, 125 µs apart,
  // and equal the native decoder's, which reads the same T_low.
  const SignalMap map = io::load_signal_map(test::source_dir() + "/config/signal-maps/rpem-native-classic.yaml");
  std::mt19937_64 rng(5);
  std::vector<core::DriveSample> samples;
  for (int k = 0; k < 40; ++k) samples.push_back(test::random_sample(rng, 16'775'000'000LL + k * 125'000LL));
  TelemetryEncoder enc(BusMode::kClassic);
  const std::vector<CanFrame> frames = test::encode_all(enc, samples);  // the clock wraps at 16.777216 s
  TelemetryDecoder native;
  const std::vector<core::DriveSample> reference = test::decode_all(native, frames);
  ASSERT_EQ(reference.size(), samples.size());
  SignalMapDecoder dec(map);
  const std::vector<core::AveragedSample> got = test::decode_all(dec, frames, 42 * kMs);
  ASSERT_EQ(got.size(), samples.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].t_ns, reference[k].t_ns) << k;
    EXPECT_EQ(got[k].t_start_ns, got[k].t_ns) << k;  // instantaneous
    if (k > 0) {
      EXPECT_EQ(got[k].t_ns - got[k - 1].t_ns, 125'000) << k;
      EXPECT_FALSE(got[k].gap_before) << k;
    }
  }
  EXPECT_TRUE(got[0].gap_before);
  EXPECT_EQ(dec.counters().stale, 0U);
}

TEST(SampleClock, TheNativeDecoderKeepsTheDrivesTimeOverSilencesLongerThanHalfAWrap) {
  // rpem's classic frames carry 24 bits of µs (a wrap every 16.777216 s). Ten samples, 10 s of silence
  // (more than half a wrap: a rule of "forward by less than half the range" reads it as a step back and
  // drops what follows as stale), ten samples, 20 s of silence (more than a wrap), ten samples; each sample's
  // frames received 3 ms after the drive stamped it. Every sample comes out at the time it was sent.
  std::mt19937_64 rng(8);
  std::vector<core::DriveSample> samples;
  for (const std::int64_t pause_ns : {0LL, 10'000'000'000LL, 20'000'000'000LL}) {
    const std::int64_t t0 = (samples.empty() ? 1'000'000'000 : samples.back().t_ns + 125'000) + pause_ns;
    for (int k = 0; k < 10; ++k) samples.push_back(test::random_sample(rng, t0 + k * 125'000LL));
  }
  TelemetryEncoder enc(BusMode::kClassic);
  TelemetryDecoder native;
  std::vector<core::DriveSample> got;
  std::array<core::DriveSample, 3> out;
  for (const core::DriveSample& sent : samples) {
    for (const CanFrame& f : test::encode_all(enc, {sent})) {
      const std::size_t n = native.decode(f, sent.t_ns + 3 * kMs, out);
      got.insert(got.end(), out.begin(), out.begin() + static_cast<long>(n));
    }
  }
  ASSERT_EQ(got.size(), samples.size());
  for (std::size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k].t_ns, samples[k].t_ns) << k;
  EXPECT_EQ(native.counters().stale, 0U);
}

TEST(SampleClock, WrapsAndASilenceLongerThanTheWrapAreCountedFromTheReceiveTimes) {
  SignalMapDecoder dec(millisecond_map());
  core::AveragedSample s;
  ASSERT_TRUE(dec.decode(at_count(250), 1000 * kMs, s));
  EXPECT_EQ(s.t_ns, 250 * kMs);  // the first sample: the drive's own reading
  // Across the wrap: 250 → 4 is 10 ms on; received 10 ms later.
  ASSERT_TRUE(dec.decode(at_count(4), 1010 * kMs, s));
  EXPECT_EQ(s.t_ns, 260 * kMs);
  // Received 3 ms after the previous, but the drive says 7 ms: the drive's step counts.
  ASSERT_TRUE(dec.decode(at_count(11), 1013 * kMs, s));
  EXPECT_EQ(s.t_ns, 267 * kMs);
  // Silent for two wraps and 10 ms (522 ms), received 90 ms late: 2·256 + 10 counts.
  ASSERT_TRUE(dec.decode(at_count(21), (1013 + 522 + 90) * kMs, s));
  EXPECT_EQ(s.t_ns, (267 + 522) * kMs);
  EXPECT_FALSE(s.gap_before);  // the estimator sees the interval and decides itself
  EXPECT_EQ(dec.counters().samples, 4U);
}

TEST(SampleClock, DuplicatedAndReorderedSamplesAreStaleDroppedAndCounted) {
  SignalMapDecoder dec(millisecond_map());
  core::AveragedSample s;
  ASSERT_TRUE(dec.decode(at_count(100), 0, s));
  ASSERT_TRUE(dec.decode(at_count(101), 1 * kMs, s));
  EXPECT_FALSE(dec.decode(at_count(101), 2 * kMs, s));  // the same sample again
  EXPECT_FALSE(dec.decode(at_count(99), 3 * kMs, s));   // an older one, late
  EXPECT_EQ(dec.counters().stale, 2U);
  ASSERT_TRUE(dec.decode(at_count(105), 5 * kMs, s));
  EXPECT_EQ(s.t_ns, 105 * kMs);
  EXPECT_TRUE(s.gap_before);  // what came between was dropped
  EXPECT_EQ(dec.counters().samples, 3U);
}

TEST(SampleClock, AClockThatRestartsIsFollowedAfterEightStaleSamples) {
  SignalMapDecoder dec(millisecond_map());
  core::AveragedSample s;
  ASSERT_TRUE(dec.decode(at_count(100), 0, s));
  // The drive resets: its clock counts from 0 again, one sample a millisecond. 0 − 100 wraps to 156
  // counts, received 1 ms on: behind the previous sample, stale — seven times, then the eighth restarts the
  // chain at the previous time plus the receive step (8 ms), with a gap.
  for (std::uint8_t k = 0; k < SampleClock::kRestartAfterStale - 1; ++k) {
    EXPECT_FALSE(dec.decode(at_count(k), (k + 1) * kMs, s)) << int(k);
  }
  ASSERT_TRUE(dec.decode(at_count(7), 8 * kMs, s));
  EXPECT_EQ(s.t_ns, (100 + 8) * kMs);
  EXPECT_TRUE(s.gap_before);
  ASSERT_TRUE(dec.decode(at_count(8), 9 * kMs, s));
  EXPECT_EQ(s.t_ns, (100 + 9) * kMs);
  EXPECT_FALSE(s.gap_before);
  EXPECT_EQ(dec.counters().stale, 7U);
  // A clock that stops (frozen telemetry) is not a restart: its samples stay stale however many come.
  for (int k = 0; k < 3 * SampleClock::kRestartAfterStale; ++k)
    EXPECT_FALSE(dec.decode(at_count(8), (10 + k) * kMs, s)) << k;
  EXPECT_EQ(dec.counters().stale, 7U + 3 * SampleClock::kRestartAfterStale);
}

TEST(SampleClock, AFloatClockIsTheDrivesSecondsAndDoesNotWrap) {
  // The clock in a frame of its own, 0x11: milliseconds as an IEEE binary64.
  SignalMapDecoder dec(io::parse_signal_map(
      kQuantities + "  - id: 0x11\n    signals:\n"
                    "      - {field: t_sample, start_bit: 0, length: 64, value_type: double, scale: 1.0e-3, unit: s}\n",
      "f.yaml"));
  auto clock = [](double ms) {
    CanFrame f;
    f.id = 0x11;
    f.len = 8;
    const auto bits = std::bit_cast<std::uint64_t>(ms);
    for (int b = 0; b < 8; ++b) f.data[b] = static_cast<std::uint8_t>(bits >> (8 * b));
    return f;
  };
  CanFrame trigger;
  trigger.id = 0x10;
  trigger.len = 8;
  core::AveragedSample s;
  EXPECT_FALSE(dec.decode(clock(5000.25), 0, s));
  ASSERT_TRUE(dec.decode(trigger, 0, s));
  EXPECT_EQ(s.t_ns, 5'000'250'000);
  EXPECT_FALSE(dec.decode(clock(65536.5), 0, s));  // an hour later by the drive, received at once
  ASSERT_TRUE(dec.decode(trigger, 1, s));
  EXPECT_EQ(s.t_ns, 65'536'500'000);
  ASSERT_FALSE(dec.decode(trigger, 2, s));  // no new time since the last sample: incomplete
  EXPECT_EQ(dec.counters().incomplete, 1U);
}

TEST(SampleClock, MapsThatCannotCountForwardAreRefused) {
  auto refused = [](const std::string& clock, const std::string& why) {
    try {
      (void)millisecond_map(clock);
      ADD_FAILURE() << clock;
    } catch (const io::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  refused("length: 8, signed: true", "unsigned, scale positive");
  refused("length: 8, scale: -1.0e-3", "unsigned, scale positive");
  EXPECT_NO_THROW((void)millisecond_map("length: 16, scale: 1.0e-4"));
  SignalMap with_two = io::parse_signal_map(kQuantities, "t.yaml");
  SignalSpec clock;
  clock.field = SampleField::kTSampleS;
  clock.start_bit = 40;
  clock.length = 8;
  clock.scale = 1e-3;
  with_two.frames[0].signals.push_back(clock);
  EXPECT_EQ(check_layout(with_two), "");
  clock.start_bit = 48;
  with_two.frames[0].signals.push_back(clock);
  EXPECT_NE(check_layout(with_two).find("t_sample is mapped twice"), std::string::npos);
}

}  // namespace
}  // namespace rpem::can
