// rpemd's VESC source without a socket (VescPoller): the poll schedule, replies turned into averaged
// windows between the replies' receive times, and what is counted — timeouts of a silent controller, late
// and unrequested replies, another poller's reads stealing the averages, windows too short to be averages.
// Frames are written byte by byte from docs/can-vesc.md (support/vesc_frames.hpp), not by our encoder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "rpem/core/reported_speed.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/vesc_source.hpp"
#include "support/temp_file.hpp"
#include "support/vesc_frames.hpp"

namespace rpem::daemon {
namespace {

using test::vesc_frames::ext;
using test::vesc_frames::kController;
using test::vesc_frames::kHost;
using test::vesc_frames::reply_frames;

constexpr std::int64_t kT0 = 1'700'000'000'000'000'000;  // a CLOCK_REALTIME instant [ns]
constexpr std::int64_t kMs = 1'000'000;

VescPoller make_poller(double rate_Hz = 200.0, double phase = 0.0) {
  VescSource::Options o;
  o.controller_id = kController;
  o.host_id = kHost;
  o.poll_rate_Hz = rate_Hz;
  o.poll_phase = phase;
  o.reply_timeout_s = std::min(0.5 / rate_Hz, 5e-3);
  return VescPoller(poller_config(o));
}

/// The reply's six frames, 20 µs apart from `t_ns`: the sample they complete, if any.
std::optional<core::AveragedSample> reply(VescPoller& p, std::int64_t t_ns) {
  core::AveragedSample s;
  bool got = false;
  std::int64_t t = t_ns;
  for (const can::CanFrame& f : reply_frames()) {
    got = p.on_frame(f, t, s) || got;
    t += 20'000;
  }
  return got ? std::optional(s) : std::nullopt;
}

/// `frames` received 20 µs apart from `t_ns` after a poll sent 300 µs before: the sample they complete, if any.
std::optional<core::AveragedSample> poll_and_receive(VescPoller& p, std::int64_t t_ns,
                                                     const std::vector<can::CanFrame>& frames) {
  p.on_time(t_ns - 300'000);
  p.polled(t_ns - 300'000, true);
  core::AveragedSample s;
  bool got = false;
  for (const can::CanFrame& f : frames) {
    got = p.on_frame(f, t_ns, s) || got;
    t_ns += 20'000;
  }
  return got ? std::optional(s) : std::nullopt;
}

/// A poll sent at t, answered 300 µs later.
std::optional<core::AveragedSample> poll_and_reply(VescPoller& p, std::int64_t t_ns) {
  p.on_time(t_ns);
  EXPECT_TRUE(p.poll_due(t_ns));
  p.polled(t_ns, true);
  return reply(p, t_ns + 300'000);
}

TEST(VescPoller, PollsWithTheDocumentedShortBuffer) {
  const VescPoller p = make_poller();
  const can::CanFrame& f = p.poll_frame();
  EXPECT_TRUE(f.extended);
  EXPECT_EQ(f.id, 0x811U);  // controller 17 | PROCESS_SHORT_BUFFER (8) << 8
  const std::vector<std::uint8_t> want = {0x7D, 0x00, 0x32, 0x00, 0x18, 0x01, 0xB3};  // host, send 0, cmd 50, mask
  ASSERT_EQ(f.len, want.size());
  EXPECT_EQ(std::vector<std::uint8_t>(f.data.begin(), f.data.begin() + f.len), want);
}

// Polls fall on k·T + φ·T of the host clock, whenever the first one went out: two instances with
// phases 0 and 0.5 poll half a period apart.
TEST(VescPoller, PollsFallOnTheScheduleWithTheirPhase) {
  VescPoller a = make_poller(200.0, 0.0), b = make_poller(200.0, 0.5);
  const std::int64_t start = kT0 + 1'234'567;
  for (VescPoller* p : {&a, &b}) {
    EXPECT_TRUE(p->poll_due(start));
    p->polled(start, true);
  }
  const std::int64_t na = a.next_poll_ns(start + 1), nb = b.next_poll_ns(start + 1);
  EXPECT_EQ(na % (5 * kMs), 0);
  EXPECT_EQ((nb - na + 5 * kMs) % (5 * kMs), 5 * kMs / 2);
  EXPECT_FALSE(a.poll_due(na - 1));
  EXPECT_TRUE(a.poll_due(na));
  EXPECT_EQ(a.wake_ns(start + 10), start + 2'500'000);  // the reply's deadline comes before the next poll
  EXPECT_EQ(a.wake_ns(na + 7), na + 7);                 // a poll overdue: now, never in the past
}

// Each reply closes the window the previous one opened; the values are VESC's, in SI.
TEST(VescPoller, RepliesBecomeWindowsBetweenTheirReceiveTimes) {
  VescPoller p = make_poller();
  EXPECT_FALSE(poll_and_reply(p, kT0).has_value());  // the first reply only opens a window
  const auto s = poll_and_reply(p, kT0 + 5 * kMs);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->t_start_ns, kT0 + 300'000);      // the previous reply's first frame
  EXPECT_EQ(s->t_ns, kT0 + 5 * kMs + 300'000);  // this reply's first frame
  EXPECT_FALSE(s->gap_before);
  EXPECT_DOUBLE_EQ(s->i_dq_A[0], -3.21);
  EXPECT_DOUBLE_EQ(s->i_dq_A[1], 27.45);
  EXPECT_DOUBLE_EQ(s->u_dq_V[0], -1.234);
  EXPECT_DOUBLE_EQ(s->u_dq_V[1], 11.873);
  EXPECT_DOUBLE_EQ(s->omega_el_rad_s, 21000.0 * 2.0 * std::numbers::pi / 60.0);
  EXPECT_DOUBLE_EQ(s->u_dc_V, 48.2);
  EXPECT_DOUBLE_EQ(s->t_winding_C, 67.8);
  EXPECT_DOUBLE_EQ(s->t_drive_C, 41.3);
  EXPECT_EQ(p.counters().polls, 2U);
  EXPECT_EQ(p.counters().samples, 1U);
  EXPECT_EQ(p.counters().timeouts + p.counters().unrequested + p.counters().stolen_reads, 0U);
}

TEST(VescPoller, AWindowWithoutAMotorSensorReadingIsASampleWithoutAWindingTemperature) {
  // GIVEN replies of a VESC whose motor sensor gives no reading (T_motor −100.0 °C, the firmware's value for none)
  // WHEN they close windows THEN each is a sample as ever, without a winding temperature, and counted.
  VescPoller p = make_poller();
  const auto frames = test::vesc_frames::reply_frames_no_motor_reading();
  EXPECT_FALSE(poll_and_receive(p, kT0, frames).has_value());  // the first reply only opens a window
  for (int k = 1; k <= 2; ++k) {
    const auto s = poll_and_receive(p, kT0 + k * 5 * kMs, frames);
    ASSERT_TRUE(s.has_value());
    EXPECT_TRUE(std::isnan(s->t_winding_C));
    EXPECT_DOUBLE_EQ(s->i_dq_A[1], 27.45);
    EXPECT_DOUBLE_EQ(s->t_drive_C, 41.3);
  }
  EXPECT_EQ(p.counters().samples, 2U);
  EXPECT_EQ(p.counters().no_motor_reading, 2U);
  // A reading again: a winding temperature again, and the count stands.
  const auto s = poll_and_receive(p, kT0 + 15 * kMs, reply_frames());
  ASSERT_TRUE(s.has_value());
  EXPECT_DOUBLE_EQ(s->t_winding_C, 67.8);
  EXPECT_EQ(p.counters().no_motor_reading, 2U);
}

// The reply's ERPM is the PLL's speed at the read: the window's mean speed is rebuilt from it and the
// previous reply's, ω̂_k + (ω̂_k − ω̂_{k−1})·(τ/h − ½) with the configured PLL's τ = k_p/k_i
// (docs/derivations.md §13, "Speed at the read"; the function itself: test_core's ReportedSpeed.*).
TEST(VescPoller, TheWindowsSpeedIsRebuiltFromThePllSpeedsAtItsTwoReads) {
  constexpr double kRadSPerErpm = 2.0 * std::numbers::pi / 60.0;
  for (const double kp : {2000.0, 1000.0}) {
    VescSource::Options o;
    o.controller_id = kController;
    o.host_id = kHost;
    o.reply_timeout_s = 2.5e-3;
    o.pll_kp = kp;  // k_i stays 30000 /s²: τ 66.7 ms, then 33.3 ms
    VescPoller p(poller_config(o));
    EXPECT_FALSE(poll_and_receive(p, kT0, test::vesc_frames::reply_frames()).has_value());  // 21000 ERPM
    const auto s = poll_and_receive(p, kT0 + 5 * kMs, test::vesc_frames::reply_frames_22000_erpm());
    ASSERT_TRUE(s.has_value());
    EXPECT_TRUE(std::isnan(p.last_accel_change_rad_s2())) << "two reads show no change of acceleration";
    const double tau = kp / 30000.0, h = 5e-3;
    EXPECT_NEAR(s->omega_el_rad_s, kRadSPerErpm * (22000.0 + 1000.0 * (tau / h - 0.5)), 1e-9) << kp;
    // The larger speed at its two reads, which R_s' test takes a sensorless frame's error at (§13, "A stall's rocking").
    EXPECT_DOUBLE_EQ(s->omega_el_at_reads_max_rad_s, kRadSPerErpm * 22000.0) << kp;
    // The same speed again: a constant speed is its own mean.
    const auto c = poll_and_receive(p, kT0 + 10 * kMs, test::vesc_frames::reply_frames_22000_erpm());
    ASSERT_TRUE(c.has_value());
    EXPECT_NEAR(c->omega_el_rad_s, kRadSPerErpm * 22000.0, 1e-9);
    // The change of acceleration the reads show (docs/derivations.md §13, "… where the acceleration changes"; the
    // error SpeedErrorDelay states from it: test_speed_error_delay.cpp): none from two reads; from three, the PLL's
    // mean acceleration went from 1000 ERPM a period to none at the window's end read. The window itself states no
    // error: it is judged once the next reply shows its change too.
    EXPECT_EQ(c->omega_el_error_rad_s, 0.0);
    EXPECT_NEAR(p.last_accel_change_rad_s2(), -kRadSPerErpm * 1000.0 / h, 1e-6) << kp;
  }
}

// A silent controller: every poll times out (counted, and the source is silent). When it answers again,
// its first reply averages everything since its last read — 25 ms here, over 2 periods + the timeout
// (12.5 ms): a long window, dropped; the next window is a sample again and follows a gap.
TEST(VescPoller, ASilentControllerTimesOutAndItsFirstLongWindowIsDropped) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  for (int k = 1; k <= 4; ++k) {
    const std::int64_t t = kT0 + std::int64_t{k} * 5 * kMs;
    p.on_time(t);
    ASSERT_TRUE(p.poll_due(t));
    p.polled(t, true);
  }
  p.on_time(kT0 + 25 * kMs);
  EXPECT_EQ(p.counters().timeouts, 4U);
  EXPECT_TRUE(p.silent());
  EXPECT_FALSE(poll_and_reply(p, kT0 + 25 * kMs).has_value());
  EXPECT_EQ(p.counters().long_windows, 1U);
  EXPECT_FALSE(p.silent());
  const auto s = poll_and_reply(p, kT0 + 30 * kMs);
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->gap_before);
  EXPECT_EQ(s->t_start_ns, kT0 + 25'300'000);
  const auto next = poll_and_reply(p, kT0 + 35 * kMs);
  ASSERT_TRUE(next.has_value());
  EXPECT_FALSE(next->gap_before);
}

// One lost reply leaves a window of two periods (≤ 2 periods + the timeout): still a sample, after a gap.
TEST(VescPoller, AWindowOverOneLostReplyIsStillASample) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  p.polled(kT0 + 5 * kMs, true);
  p.on_time(kT0 + 8 * kMs);
  const auto s = poll_and_reply(p, kT0 + 10 * kMs);
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->gap_before);
  EXPECT_EQ(s->t_ns - s->t_start_ns, 10 * kMs);
  EXPECT_EQ(p.counters().long_windows, 0U);
}

/// The estimator's reply (reply_frames()) with i_d, i_q, v_d, v_q all 0 — what the firmware sends for a
/// read with no control cycle since the previous one (NaN → 0) — written byte by byte; CRC 0x37B7 from
/// Python's binascii.crc_hqx over the 31 bytes.
std::vector<can::CanFrame> empty_reply_frames() {
  return {ext(0x57D, {0x00, 0x32, 0x00, 0x18, 0x01, 0xB3, 0x01, 0x9D}),
          ext(0x57D, {0x07, 0x02, 0xA6, 0x00, 0x00, 0x00, 0x00, 0x00}),
          ext(0x57D, {0x0E, 0x00, 0x00, 0x00, 0x00, 0x00, 0x52, 0x08}),
          ext(0x57D, {0x15, 0x01, 0xE2, 0x00, 0x00, 0x00, 0x00, 0x00}),
          ext(0x57D, {0x1C, 0x00, 0x00, 0x00}),
          ext(0x77D, {0x11, 0x01, 0x00, 0x1F, 0x37, 0xB7})};
}

// A reply of no control cycle (a firmware that did not run since the previous read, as a stalled
// emulator would answer) never reaches the estimator, however long its window.
TEST(VescPoller, AReplyOfNoControlCycleIsCountedAndNeverASample) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  p.polled(kT0 + 5 * kMs, true);
  core::AveragedSample s;
  bool got = false;
  for (const can::CanFrame& f : empty_reply_frames()) got = p.on_frame(f, kT0 + 5'300'000, s) || got;
  EXPECT_FALSE(got);
  EXPECT_EQ(p.counters().empty_reads, 1U);
  EXPECT_EQ(p.decoder().counters().crc_error, 0U);
  EXPECT_EQ(p.counters().timeouts, 0U);  // it was a reply: the poll is answered
  const auto next = poll_and_reply(p, kT0 + 10 * kMs);
  ASSERT_TRUE(next.has_value());
  EXPECT_TRUE(next->gap_before);
  EXPECT_EQ(next->t_start_ns, kT0 + 5'300'000);
  DiagnosticsRows rows;
  report_vesc_counters(p, rows);
  EXPECT_EQ(rows.get(&diagnostics_t::vesc_empty_reads), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::vesc_long_windows), 0);
}

// A reply after its poll timed out is late, and still a window (it ends a read of the controller); it is
// the read the timeout feared lost, so the chain holds (no gap).
TEST(VescPoller, AReplyAfterItsTimeoutIsLateAndStillUsed) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  p.polled(kT0 + 5 * kMs, true);
  p.on_time(kT0 + 8 * kMs);  // timeout 2.5 ms
  EXPECT_EQ(p.counters().timeouts, 1U);
  const auto s = reply(p, kT0 + 8'500'000);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(p.counters().late, 1U);
  EXPECT_EQ(p.counters().unrequested, 0U);
  EXPECT_EQ(s->t_start_ns, kT0 + 300'000);
  EXPECT_FALSE(s->gap_before);
}

// Replies that take longer than a period on the bus (1 kHz, reply_timeout_s 0.9 ms or 1 ms): each begins before the
// next poll goes out and completes after it. Each is its own poll's, answered in time — no timeout, no late reply —
// and the windows chain without gaps. (Before 2026-12-01 every poll counted as a timeout and every reply as late.)
TEST(VescPoller, RepliesStraddlingTheNextPollAnswerTheirOwnAndChain) {
  for (const double timeout_s : {0.9e-3, 1e-3}) {  // the default at 1 kHz, and the most allowed
    SCOPED_TRACE(timeout_s);
    VescSource::Options o;
    o.controller_id = kController;
    o.host_id = kHost;
    o.poll_rate_Hz = 1000.0;
    o.reply_timeout_s = timeout_s;
    VescPoller p(poller_config(o));
    const std::vector<can::CanFrame> frames = reply_frames();
    std::vector<core::AveragedSample> samples;
    // Poll k goes out at k ms; its reply's six frames arrive 130 µs apart from 0.8 ms after it: two before
    // the next poll, four after it.
    const auto deliver = [&](int poll, std::int64_t from_ns, std::int64_t to_ns) {
      for (std::size_t i = 0; i < frames.size(); ++i) {
        const std::int64_t rx = kT0 + poll * kMs + 800'000 + static_cast<std::int64_t>(i) * 130'000;
        if (rx < from_ns || rx >= to_ns) continue;
        p.on_time(rx);
        core::AveragedSample s;
        if (p.on_frame(frames[i], rx, s)) samples.push_back(s);
      }
    };
    for (int k = 0; k <= 21; ++k) {
      const std::int64_t t = kT0 + k * kMs;
      if (k > 0) deliver(k - 1, t - kMs, t);
      p.on_time(t);
      ASSERT_TRUE(p.poll_due(t));
      p.polled(t, true);
      if (k > 0) deliver(k - 1, t, t + kMs);
    }
    EXPECT_EQ(p.counters().polls, 22U);
    EXPECT_EQ(p.counters().timeouts, 0U);
    EXPECT_EQ(p.counters().late, 0U);
    EXPECT_EQ(p.counters().unrequested, 0U);
    EXPECT_EQ(p.decoder().counters().out_of_order + p.decoder().counters().length_mismatch, 0U);
    ASSERT_EQ(samples.size(), 20U);  // the first reply opens the first window
    for (std::size_t i = 0; i < samples.size(); ++i) {
      EXPECT_EQ(samples[i].t_ns - samples[i].t_start_ns, kMs) << i;
      if (i > 0) {
        EXPECT_FALSE(samples[i].gap_before) << i;
        EXPECT_EQ(samples[i].t_start_ns, samples[i - 1].t_ns) << i;
      }
    }
  }
}

/// A poller whose reply timeout is its whole period (the most `reply_timeout_s` allows), `rate_Hz` polls a second.
VescPoller make_poller_timeout_a_period(double rate_Hz) {
  VescSource::Options o;
  o.controller_id = kController;
  o.host_id = kHost;
  o.poll_rate_Hz = rate_Hz;
  o.reply_timeout_s = 1.0 / rate_Hz;
  return VescPoller(poller_config(o));
}

constexpr std::int64_t kPeriod10Hz = 100 * kMs;

/// Polls 0…last at 10 Hz, each answered 3 ms after it but poll `lost`: the samples the replies close.
std::vector<core::AveragedSample> poll_at_10_Hz_answered_in_3_ms(VescPoller& p, int last, int lost) {
  constexpr std::int64_t kLatency = 3 * kMs;
  std::vector<core::AveragedSample> samples;
  for (int k = 0; k <= last; ++k) {
    const std::int64_t t = kT0 + k * kPeriod10Hz;
    p.on_time(t);
    EXPECT_TRUE(p.poll_due(t)) << k;
    p.polled(t, true);
    if (k == lost) continue;
    p.on_time(t + kLatency);
    if (const auto s = reply(p, t + kLatency)) samples.push_back(*s);
  }
  return samples;
}

// 10 Hz, the timeout a whole period: the first poll goes unanswered (the controller not yet up), every later one is
// answered 3 ms after it. Each reply began after its own poll went out, so it is that poll's: one timeout, no late
// reply, and the windows chain without gaps. (Taken as the timed-out poll's, every reply would be "late" and every
// poll a timeout for the rest of the run: 20 and 20 here.)
TEST(VescPoller, APollLostOnceLeavesNoChainOfLateReplies) {
  VescPoller p = make_poller_timeout_a_period(10.0);
  const std::vector<core::AveragedSample> samples = poll_at_10_Hz_answered_in_3_ms(p, 20, 0);
  EXPECT_EQ(p.counters().polls, 21U);
  EXPECT_EQ(p.counters().timeouts, 1U);
  EXPECT_EQ(p.counters().late, 0U);
  EXPECT_EQ(p.counters().unrequested, 0U);
  EXPECT_FALSE(p.silent());
  ASSERT_EQ(samples.size(), 19U);  // the first reply opens the first window
  for (const core::AveragedSample& s : samples) {
    EXPECT_EQ(s.t_ns - s.t_start_ns, kPeriod10Hz);
    EXPECT_FALSE(s.gap_before);
  }
}

// The same poller, replies prompt, one of them lost (poll 5's): the window after it spans the read the controller may
// have made for it, so it follows a gap; the reply to poll 6 is poll 6's, not a late one for poll 5.
TEST(VescPoller, AReplyLostAmongPromptOnesKeepsItsGap) {
  VescPoller p = make_poller_timeout_a_period(10.0);
  const std::vector<core::AveragedSample> samples = poll_at_10_Hz_answered_in_3_ms(p, 8, 5);
  EXPECT_EQ(p.counters().timeouts, 1U);
  EXPECT_EQ(p.counters().late, 0U);
  ASSERT_EQ(samples.size(), 7U);  // replies 1-4 and 6-8 close windows
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const bool after_loss = i == 4;  // the window from reply 4 to reply 6
    EXPECT_EQ(samples[i].gap_before, after_loss) << i;
    EXPECT_EQ(samples[i].t_ns - samples[i].t_start_ns, (after_loss ? 2 : 1) * kPeriod10Hz) << i;
  }
}

// Another poller reading our controller on the bus (node 0x42, the same poll the docs show for us): its
// read resets the averages, so it is counted and our next window starts at it.
TEST(VescPoller, AnotherPollersReadIsCountedAndStartsTheWindow) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  core::AveragedSample unused;
  const can::CanFrame theirs = ext(0x811, {0x42, 0x00, 0x32, 0x00, 0x00, 0x00, 0x30});  // i_d, i_q only
  EXPECT_FALSE(p.on_frame(theirs, kT0 + 2 * kMs, unused));
  // COMM_GET_VALUES (4) resets them too; a read of another controller (18) does not concern us.
  EXPECT_FALSE(p.on_frame(ext(0x812, {0x42, 0x00, 0x04}), kT0 + 2'100'000, unused));
  EXPECT_EQ(p.counters().stolen_reads, 1U);
  EXPECT_FALSE(p.on_frame(ext(0x811, {0x42, 0x00, 0x04}), kT0 + 2'200'000, unused));
  EXPECT_EQ(p.counters().stolen_reads, 2U);
  const auto s = poll_and_reply(p, kT0 + 5 * kMs);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->t_start_ns, kT0 + 2'200'000);
  EXPECT_EQ(s->t_ns, kT0 + 5'300'000);
  // The other poller's reply goes to its id (0x42 | FILL_RX_BUFFER << 8): foreign, not a reply to us.
  EXPECT_FALSE(p.on_frame(ext(0x542, {0x00, 0x32, 0x00, 0x00, 0x00, 0x30, 0x00, 0x00}), kT0 + 6 * kMs, unused));
  EXPECT_GE(p.decoder().counters().foreign, 4U);
}

// A poller sharing our host id: its replies reach us without a poll of ours outstanding.
TEST(VescPoller, RepliesWeDidNotAskForAreCountedAndCloseTheirWindow) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  const auto s = reply(p, kT0 + 2 * kMs);  // no poll of ours
  EXPECT_EQ(p.counters().unrequested, 1U);
  ASSERT_TRUE(s.has_value());
  const auto ours = poll_and_reply(p, kT0 + 5 * kMs);
  ASSERT_TRUE(ours.has_value());
  EXPECT_EQ(ours->t_start_ns, kT0 + 2 * kMs);  // since the read that answered the other poller
  EXPECT_EQ(p.counters().unrequested, 1U);
}

// A read right before ours leaves (nearly) no control cycles in our window: not an average, dropped.
TEST(VescPoller, AWindowTooShortToBeAnAverageIsDroppedAndFollowedByAGap) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  core::AveragedSample unused;
  EXPECT_FALSE(p.on_frame(ext(0x811, {0x42, 0x00, 0x04}), kT0 + 5'250'000, unused));
  EXPECT_FALSE(poll_and_reply(p, kT0 + 5 * kMs).has_value());
  EXPECT_EQ(p.counters().short_windows, 1U);
  const auto s = poll_and_reply(p, kT0 + 10 * kMs);
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->gap_before);
}

// A broken reply (its CRC's last byte flipped) is the decoder's crc_error; the poll then times out.
TEST(VescPoller, ABrokenReplyIsCountedAndItsPollTimesOut) {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  p.polled(kT0 + 5 * kMs, true);
  std::vector<can::CanFrame> frames = reply_frames();
  frames.back().data[5] ^= 0x01;
  core::AveragedSample unused;
  for (const can::CanFrame& f : frames) EXPECT_FALSE(p.on_frame(f, kT0 + 5'300'000, unused));
  p.on_time(kT0 + 8 * kMs);
  EXPECT_EQ(p.decoder().counters().crc_error, 1U);
  EXPECT_EQ(p.counters().timeouts, 1U);
  DiagnosticsRows rows;
  report_vesc_counters(p, rows);
  EXPECT_EQ(rows.get(&diagnostics_t::can_crc_error), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::vesc_timeouts), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::vesc_polls), 2);
  EXPECT_EQ(rows.get(&diagnostics_t::vesc_replies), 0);
}

/// 200 Hz (timeout 2.5 ms): poll 0 answered, poll 1 (at 5 ms) answered from 5.3 ms by all but the reply's last frame.
VescPoller poll_with_a_reply_begun_and_never_completed() {
  VescPoller p = make_poller();
  (void)poll_and_reply(p, kT0);
  p.on_time(kT0 + 5 * kMs);
  p.polled(kT0 + 5 * kMs, true);
  const std::vector<can::CanFrame> frames = reply_frames();
  core::AveragedSample unused;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i)
    EXPECT_FALSE(p.on_frame(frames[i], kT0 + 5'300'000 + static_cast<std::int64_t>(i) * 20'000, unused));
  return p;
}

// A reply whose first frame came in time answers its poll: its deadline (7.5 ms) passes without a timeout, and
// the poll keeps the second slot when the next goes out. Its last frame never comes: it times out a period after
// its deadline (12.5 ms), and the next window follows a gap (the controller read and reset for it).
TEST(VescPoller, AReplyBegunInTimeButNeverCompletedTimesOutAPeriodAfterItsDeadline) {
  VescPoller p = poll_with_a_reply_begun_and_never_completed();
  p.on_time(kT0 + 8 * kMs);
  EXPECT_EQ(p.counters().timeouts, 0U);
  EXPECT_EQ(p.wake_ns(kT0 + 8 * kMs), kT0 + 10 * kMs);  // the next poll, before the extended deadline
  p.on_time(kT0 + 10 * kMs);
  p.polled(kT0 + 10 * kMs, true);
  EXPECT_EQ(p.wake_ns(kT0 + 10'100'000), kT0 + 12'500'000);  // the new poll's deadline and the second slot's
  p.on_time(kT0 + 12'500'000);
  EXPECT_EQ(p.counters().timeouts, 0U);
  p.on_time(kT0 + 12'500'001);
  EXPECT_EQ(p.counters().timeouts, 2U);       // the second slot's, and the new poll's (its reply has not begun)
  const auto s = reply(p, kT0 + 12'600'000);  // a window of 12.3 ms: within the 12.5 ms one lost read explains
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(p.counters().late, 1U);  // the newer poll's reply, after its timeout
  EXPECT_TRUE(s->gap_before);
}

// The same, but the next poll's reply begins while the second slot still waits: the decoder restarts at it, so the
// unfinished reply can no longer complete and its poll times out there; the new reply is its own poll's, after a gap.
TEST(VescPoller, AReplyBegunInTimeButNeverCompletedTimesOutWhenTheNextBegins) {
  VescPoller p = poll_with_a_reply_begun_and_never_completed();
  p.on_time(kT0 + 10 * kMs);
  p.polled(kT0 + 10 * kMs, true);
  const auto s = reply(p, kT0 + 10'300'000);
  EXPECT_EQ(p.counters().timeouts, 1U);
  EXPECT_EQ(p.counters().late, 0U);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->t_start_ns, kT0 + 300'000);
  EXPECT_EQ(s->t_ns, kT0 + 10'300'000);
  EXPECT_TRUE(s->gap_before);
  p.on_time(kT0 + 20 * kMs);
  EXPECT_EQ(p.counters().timeouts, 1U);
}

/// What a 1 kHz poller (the default 0.9 ms timeout) counts and delivers over 2 000 polls on a 1 Mbit/s bus: each
/// reply begins 0.05–0.85 ms after its poll (uniform), or when the previous reply has left the bus, and its six
/// frames come 130 µs apart, so that most replies straddle the next poll; the last frame of each reply is lost with
/// probability `p_lost`. Returns the samples, and in `lost` the indices of the replies that lost their frame.
std::vector<core::AveragedSample> run_1_kHz_random_replies(VescPoller& p, double p_lost, unsigned seed,
                                                           std::vector<int>& lost) {
  struct Rx {
    std::int64_t t;
    std::size_t frame;
  };
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::vector<can::CanFrame> frames = reply_frames();
  constexpr std::int64_t kFrameNs = 130'000;
  std::vector<Rx> on_bus;
  std::vector<core::AveragedSample> samples;
  std::int64_t bus_free = 0;
  const auto deliver_until = [&](std::int64_t now) {
    std::size_t k = 0;
    for (; k < on_bus.size() && on_bus[k].t <= now; ++k) {
      p.on_time(on_bus[k].t);
      core::AveragedSample s;
      if (p.on_frame(frames[on_bus[k].frame], on_bus[k].t, s)) samples.push_back(s);
    }
    on_bus.erase(on_bus.begin(), on_bus.begin() + static_cast<std::ptrdiff_t>(k));
  };
  for (int poll = 0; poll < 2000; ++poll) {
    const std::int64_t t = kT0 + poll * kMs;
    deliver_until(t - 1);
    p.on_time(t);
    EXPECT_TRUE(p.poll_due(t)) << poll;
    p.polled(t, true);
    const std::int64_t start =
        std::max(t + static_cast<std::int64_t>((0.05 + 0.8 * unit(rng)) * static_cast<double>(kMs)), bus_free);
    const bool lose_last = unit(rng) < p_lost;
    if (lose_last) lost.push_back(poll);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      if (!(lose_last && i + 1 == frames.size())) on_bus.push_back({start + static_cast<std::int64_t>(i) * kFrameNs, i});
    }
    bus_free = start + static_cast<std::int64_t>(frames.size()) * kFrameNs;
  }
  deliver_until(kT0 + 2002 * kMs);  // the last reply has left the bus by 2 001.5 ms
  p.on_time(kT0 + 2003 * kMs);      // and its poll timed out, were it lost
  return samples;
}

VescPoller make_poller_1_kHz() {
  VescSource::Options o;
  o.controller_id = kController;
  o.host_id = kHost;
  o.poll_rate_Hz = 1000.0;
  o.reply_timeout_s = 0.9e-3;  // the default at 1 kHz (TheDefaultTimeoutLeavesTheReplyMostOfThePeriod)
  return VescPoller(poller_config(o));
}

// Every reply begins within the timeout (at most 0.85 ms after its poll, and the previous reply has left the bus by
// 0.5 ms after it), so every poll is answered: no timeout, no late or unrequested reply, whatever the replies' jitter
// and however many of them straddle the next poll; the windows run from reply to reply without a gap.
TEST(VescPoller, RandomRepliesBegunInTimeAreAllAnsweredAndChain) {
  VescPoller p = make_poller_1_kHz();
  std::vector<int> lost;
  const std::vector<core::AveragedSample> samples = run_1_kHz_random_replies(p, 0.0, 1, lost);
  EXPECT_EQ(p.counters().polls, 2000U);
  EXPECT_EQ(p.counters().timeouts, 0U);
  EXPECT_EQ(p.counters().late, 0U);
  EXPECT_EQ(p.counters().unrequested, 0U);
  ASSERT_EQ(samples.size(), 1999U);  // the first reply opens the first window
  for (std::size_t i = 1; i < samples.size(); ++i) {
    EXPECT_FALSE(samples[i].gap_before) << i;
    EXPECT_EQ(samples[i].t_start_ns, samples[i - 1].t_ns) << i;
  }
}

// The same with 2 % of the replies losing their last frame: each such poll times out (its reply never completes),
// and only those; the window after each follows a gap — the controller read and reset for the lost reply — and no
// other window does.
TEST(VescPoller, RandomRepliesThatLoseTheirLastFrameTimeOutAndLeaveAGap) {
  VescPoller p = make_poller_1_kHz();
  std::vector<int> lost;
  const std::vector<core::AveragedSample> samples = run_1_kHz_random_replies(p, 0.02, 2, lost);
  ASSERT_GT(lost.size(), 20U);
  EXPECT_EQ(p.counters().timeouts, lost.size());
  EXPECT_EQ(p.counters().late, 0U);
  EXPECT_EQ(p.counters().unrequested, 0U);
  // The samples in order, each closed by the next completed reply after the first; which follow a gap.
  std::vector<bool> expected_gaps;
  bool opened = false, gap = false;
  for (int poll = 0; poll < 2000; ++poll) {
    if (std::find(lost.begin(), lost.end(), poll) != lost.end()) {
      gap = gap || opened;
    } else if (!opened) {
      opened = true;  // the first completed reply opens the first window
    } else {
      expected_gaps.push_back(gap);
      gap = false;
    }
  }
  ASSERT_EQ(samples.size(), expected_gaps.size());
  for (std::size_t i = 0; i < samples.size(); ++i) EXPECT_EQ(samples[i].gap_before, expected_gaps[i]) << i;
}

TEST(VescPoller, TheDefaultTimeoutLeavesTheReplyMostOfThePeriod) {
  for (double rate : {50.0, 200.0, 1000.0}) {
    const test::TempFile config("rpemd-vesc-timeout.yaml",
                                "daemon:\n  source:\n    type: vesc\n    vesc: {interface: can0, "
                                "controller_id: 17, poll_rate_Hz: " +
                                    std::to_string(rate) + "}\n");
    const DaemonConfig c = load_daemon_config(config.path());
    EXPECT_NEAR(std::get<VescSource::Options>(c.fixed.source).reply_timeout_s, std::min(0.9 / rate, 0.02), 1e-12) << rate;
  }
}

TEST(VescPoller, AnUnsentPollIsCountedAndNotAwaited) {
  VescPoller p = make_poller();
  p.polled(kT0, false);
  p.on_time(kT0 + 10 * kMs);
  EXPECT_EQ(p.counters().send_failures, 1U);
  EXPECT_EQ(p.counters().polls, 0U);
  EXPECT_EQ(p.counters().timeouts, 0U);
}

}  // namespace
}  // namespace rpem::daemon

namespace rpem::daemon {
namespace {

TEST(VescSource, ReplyGatherIsASixteenthOfThePollPeriodAtMostOneMillisecond) {
  EXPECT_EQ(reply_gather_ns(17'857'143), 1'000'000);  // 56 Hz: 1/16 would be 1.12 ms
  EXPECT_EQ(reply_gather_ns(16'000'000), 1'000'000);  // 62.5 Hz: exactly 1 ms either way
  EXPECT_EQ(reply_gather_ns(1'000'000), 62'500);      // 1 kHz
  EXPECT_EQ(reply_gather_ns(500'000), 31'250);        // 2 kHz, the highest poll rate
}

}  // namespace
}  // namespace rpem::daemon
