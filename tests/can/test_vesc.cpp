// Conformance of the VESC decoder against frames written byte by byte from docs/can-vesc.md (which cites
// vedderb/bldc: comm/comm_can.c comm_can_send_buffer, decode_msg, comm_can_send_status1…6; comm/commands.c
// commands_process_packet, case COMM_GET_VALUES_SELECTIVE; util/buffer.c; util/crc.c crc16). The CRC of
// the reply vector was computed with Python's binascii.crc_hqx(payload, 0) (CRC-16/XMODEM, check value
// 0x31C3 for "123456789"), not with our code. Then every kind of bad input, counted by kind.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "rpem/can/decoder.hpp"
#include "rpem/can/e2e.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/can/vesc.hpp"
#include "support/vesc_frames.hpp"

namespace rpem::can::vesc {
namespace {

using test::vesc_frames::ext;
using test::vesc_frames::kController;
using test::vesc_frames::kHost;  // the poller (rpemd)
using test::vesc_frames::reply_frames;

std::vector<VescDecoder::Event> feed(VescDecoder& dec, const std::vector<CanFrame>& frames) {
  std::vector<VescDecoder::Event> events;
  for (const CanFrame& f : frames) events.push_back(dec.decode(f));
  return events;
}

TEST(Vesc, PollRequestIsAShortBufferToTheController) {
  const CanFrame f = values_request(kController, kHost, kEstimatorMask);
  EXPECT_TRUE(f.extended);
  EXPECT_EQ(f.id, 0x811U);  // 17 | CAN_PACKET_PROCESS_SHORT_BUFFER (8) << 8
  ASSERT_EQ(f.len, 7);
  const std::vector<std::uint8_t> want = {0x7D, 0x00, 0x32, 0x00, 0x18, 0x01, 0xB3};
  EXPECT_EQ(std::vector<std::uint8_t>(f.data.begin(), f.data.begin() + 7), want);
  EXPECT_EQ(kEstimatorMask, 0x001801B3U);
}

TEST(Vesc, ReassemblesAndDecodesAGetValuesSelectiveReply) {
  VescDecoder dec(kController, kHost);
  const auto events = feed(dec, reply_frames());
  for (std::size_t k = 0; k + 1 < events.size(); ++k) EXPECT_EQ(events[k], VescDecoder::Event::kNone);
  ASSERT_EQ(events.back(), VescDecoder::Event::kValues);
  const Values& v = dec.values();
  EXPECT_EQ(v.mask, 0x001801B3U);
  EXPECT_DOUBLE_EQ(v.temp_fet_C, 41.3);
  EXPECT_DOUBLE_EQ(v.temp_motor_C, 67.8);
  EXPECT_DOUBLE_EQ(v.i_d_A, -3.21);
  EXPECT_DOUBLE_EQ(v.i_q_A, 27.45);
  EXPECT_DOUBLE_EQ(v.erpm, 21000.0);
  EXPECT_DOUBLE_EQ(v.v_in_V, 48.2);
  EXPECT_DOUBLE_EQ(v.v_d_V, -1.234);
  EXPECT_DOUBLE_EQ(v.v_q_V, 11.873);
  EXPECT_TRUE(std::isnan(v.current_motor_A));  // not asked for
  EXPECT_EQ(dec.counters().replies, 1U);
  EXPECT_EQ(dec.counters().frames, 6U);

  const core::AveragedSample s = to_averaged_sample(v, 1'000'000, 6'000'000);
  EXPECT_EQ(s.t_start_ns, 1'000'000);
  EXPECT_EQ(s.t_ns, 6'000'000);
  EXPECT_DOUBLE_EQ(s.omega_el_rad_s, 21000.0 * 2.0 * std::numbers::pi / 60.0);  // ERPM → rad/s
  EXPECT_DOUBLE_EQ(s.i_dq_A[1], 27.45);
  EXPECT_DOUBLE_EQ(s.u_dq_V[0], -1.234);
  EXPECT_DOUBLE_EQ(s.u_dc_V, 48.2);
  EXPECT_DOUBLE_EQ(s.t_winding_C, 67.8);
  EXPECT_DOUBLE_EQ(s.t_drive_C, 41.3);
  EXPECT_TRUE(std::isnan(s.t_magnet_C));
}

TEST(Vesc, AMotorTemperatureOfMinus100IsNoWindingReading) {
  // GIVEN the reply of a VESC without a reading of its motor sensor (T_motor −100.0 °C: the firmware's value for
  // none) WHEN decoded THEN the reply holds it as sent, and the sample has no winding temperature, the rest as ever.
  VescDecoder dec(kController, kHost);
  ASSERT_EQ(feed(dec, test::vesc_frames::reply_frames_no_motor_reading()).back(), VescDecoder::Event::kValues);
  EXPECT_EQ(dec.values().temp_motor_C, kNoMotorReading_C);
  EXPECT_TRUE(is_no_motor_reading(dec.values().temp_motor_C));
  const core::AveragedSample s = to_averaged_sample(dec.values(), 1'000'000, 6'000'000);
  EXPECT_TRUE(std::isnan(s.t_winding_C));
  EXPECT_DOUBLE_EQ(s.t_drive_C, 41.3);
  EXPECT_DOUBLE_EQ(s.i_dq_A[1], 27.45);
  // A tenth of a degree away is a reading.
  EXPECT_FALSE(is_no_motor_reading(-99.9));
}

TEST(Vesc, ShortReplyInOneFrame) {
  // Mask bit 15 (fault code 3): a 6-byte reply, sent as PROCESS_SHORT_BUFFER [sender][commands_send][payload].
  VescDecoder dec(kController, kHost, bit(kFault));
  EXPECT_EQ(dec.decode(ext(0x87D, {0x11, 0x01, 0x32, 0x00, 0x00, 0x80, 0x00, 0x03})), VescDecoder::Event::kValues);
  EXPECT_EQ(dec.values().mask, 0x8000U);
  EXPECT_EQ(dec.values().fault, 3);
}

TEST(Vesc, StatusBroadcasts) {
  VescDecoder dec(kController, kHost);
  // STATUS (9): ERPM −1500, current 12.3 A, duty 0.456.
  ASSERT_EQ(dec.decode(test::vesc_frames::status1()), VescDecoder::Event::kStatus);
  EXPECT_EQ(dec.status().number, 1);
  EXPECT_DOUBLE_EQ(dec.status().erpm, -1500.0);
  EXPECT_DOUBLE_EQ(dec.status().current_A, 12.3);
  EXPECT_DOUBLE_EQ(dec.status().duty, 0.456);
  // STATUS_4 (16): T_fet 35.5 °C, T_motor 80.1 °C, input current 5.5 A, PID position 90°.
  ASSERT_EQ(dec.decode(test::vesc_frames::status4()), VescDecoder::Event::kStatus);
  EXPECT_EQ(dec.status().number, 4);
  EXPECT_DOUBLE_EQ(dec.status().temp_fet_C, 35.5);
  EXPECT_DOUBLE_EQ(dec.status().temp_motor_C, 80.1);
  EXPECT_DOUBLE_EQ(dec.status().current_in_A, 5.5);
  EXPECT_DOUBLE_EQ(dec.status().pid_pos_deg, 90.0);
  // STATUS_5 (27): tachometer 123456, V_in 50.4 V, reserved.
  ASSERT_EQ(dec.decode(test::vesc_frames::status5()), VescDecoder::Event::kStatus);
  EXPECT_EQ(dec.status().number, 5);
  EXPECT_EQ(dec.status().tachometer, 123456);
  EXPECT_DOUBLE_EQ(dec.status().v_in_V, 50.4);
  // STATUS_2, _3, _6.
  ASSERT_EQ(dec.decode(ext(0xE11, {0x00, 0x00, 0x30, 0x39, 0x00, 0x00, 0x00, 0x64})), VescDecoder::Event::kStatus);
  EXPECT_DOUBLE_EQ(dec.status().amp_hours_Ah, 1.2345);
  EXPECT_DOUBLE_EQ(dec.status().amp_hours_charged_Ah, 0.01);
  ASSERT_EQ(dec.decode(ext(0xF11, {0x00, 0x01, 0x86, 0xA0, 0x00, 0x00, 0x00, 0x00})), VescDecoder::Event::kStatus);
  EXPECT_DOUBLE_EQ(dec.status().watt_hours_Wh, 10.0);
  ASSERT_EQ(dec.decode(ext(0x3A11, {0x0C, 0xE4, 0x00, 0x00, 0x00, 0x00, 0xFC, 0x18})), VescDecoder::Event::kStatus);
  EXPECT_DOUBLE_EQ(dec.status().adc_V[0], 3.3);
  EXPECT_DOUBLE_EQ(dec.status().adc_V[3], -1.0);
  EXPECT_EQ(dec.counters().statuses, 6U);
}

// The kernel's rule for CAN_RAW_FILTER (linux Documentation/networking/can.rst, "RAW Socket Option
// CAN_RAW_FILTER"): a frame is received when <received_can_id> & mask == can_id & mask for any filter; the
// received can_id has bit 31 (CAN_EFF_FLAG) set for a 29-bit id and bit 30 (CAN_RTR_FLAG) for a remote frame.
bool kernel_passes(std::span<const KernelFilter> filters, const CanFrame& f, bool remote = false) {
  const std::uint32_t can_id = f.id | (f.extended ? 0x80000000U : 0U) | (remote ? 0x40000000U : 0U);
  return std::any_of(filters.begin(), filters.end(),
                     [&](const KernelFilter& k) { return (can_id & k.mask) == (k.id & k.mask); });
}

TEST(Vesc, KernelFiltersPassWhatThePollerReadsAndNothingElse) {
  const auto filters = kernel_filters(kController, kHost);
  // Passed: every frame of a reply to us (FILL_RX_BUFFER 5, PROCESS_RX_BUFFER 7), the other buffer packets
  // addressed to us (FILL_RX_BUFFER_LONG 6, PROCESS_SHORT_BUFFER 8), the controller's statuses 1-6, a second
  // poller's read of our controller and a read of every controller (id 255).
  for (const CanFrame& f : test::vesc_frames::reply_frames()) EXPECT_TRUE(kernel_passes(filters, f)) << std::hex << f.id;
  EXPECT_TRUE(kernel_passes(filters, ext(0x67D, {0x00, 0x00, 0x32})));
  EXPECT_TRUE(kernel_passes(filters, ext(0x87D, {0x11, 0x00, 0x32})));
  for (std::uint32_t status : {9U, 14U, 15U, 16U, 27U, 58U}) {
    EXPECT_TRUE(kernel_passes(filters, ext((status << 8) | kController, {0, 0, 0, 0, 0, 0, 0, 0}))) << status;
  }
  EXPECT_TRUE(kernel_passes(filters, test::vesc_frames::status4()));
  EXPECT_TRUE(kernel_passes(filters, values_request(kController, 0x42, kEstimatorMask)));       // another host's poll
  EXPECT_TRUE(kernel_passes(filters, ext(0x8FF, {0x42, 0x00, 0x32, 0x00, 0x18, 0x01, 0xB3})));  // to every VESC

  // Kept in the kernel: replies to another host (0x42), another controller's statuses and replies, our
  // own ids as standard (11-bit) frames, a remote frame to us, and everything of other protocols.
  EXPECT_FALSE(kernel_passes(filters, ext(0x542, {0x00, 0x32})));
  EXPECT_FALSE(kernel_passes(filters, ext(0x742, {0x11, 0x01, 0x00, 0x1F, 0x08, 0xF7})));
  EXPECT_FALSE(kernel_passes(filters, ext(0x912, {0, 0, 0, 0, 0, 0, 0, 0})));
  EXPECT_FALSE(kernel_passes(filters, ext(0x1012, {0, 0, 0, 0, 0, 0, 0, 0})));
  CanFrame standard = ext(0x57D, {0x00, 0x32});
  standard.extended = false;
  EXPECT_FALSE(kernel_passes(filters, standard));
  standard.id = kController;
  EXPECT_FALSE(kernel_passes(filters, standard));
  EXPECT_FALSE(kernel_passes(filters, ext(0x57D, {}), /*remote=*/true));
  EXPECT_FALSE(kernel_passes(filters, ext(0x18FF0001, {1, 2, 3})));  // a J1939-style id of another node
}

// The controller's side. VESC's id layout (vedderb/bldc comm/comm_can.c: comm_can_send_buffer sends
// `controller_id | (CAN_PACKET_PROCESS_SHORT_BUFFER << 8)`, decode_msg reads `id = eid & 0xFF`, `cmd = eid >> 8`
// and answers `id == app controller id || id == 255`; datatypes.h: CAN_PACKET_PROCESS_SHORT_BUFFER = 8): the
// addressee in bits 0-7, the packet in bits 8-15. Every (packet, addressee) pair is built by hand from that
// layout and put through the kernel's arithmetic; only PROCESS_SHORT_BUFFER to the controller or to 255 passes.
TEST(Vesc, ControllerKernelFiltersPassCommandsToItOrToAllAndNothingElse) {
  constexpr std::uint32_t kShortBuffer = 8;
  for (const std::uint32_t controller : {1U, 7U, 12U, 254U}) {
    const auto filters = controller_kernel_filters(static_cast<std::uint8_t>(controller));
    int passed = 0;
    for (std::uint32_t packet = 0; packet <= 0xFF; ++packet) {
      for (std::uint32_t addressee = 0; addressee <= 0xFF; ++addressee) {
        const CanFrame f = ext(addressee | (packet << 8), {0x65, 0x00, 0x32, 0x00, 0x18, 0x01, 0xB3});
        const bool expected = packet == kShortBuffer && (addressee == controller || addressee == 255);
        ASSERT_EQ(kernel_passes(filters, f), expected) << "controller " << controller << std::hex << " id 0x" << f.id;
        passed += expected;
      }
    }
    EXPECT_EQ(passed, 2);
  }
  // Twelve drives on one bus: controller 7 is woken by its own poll (0x807) and a poll of all (0x8FF), not by
  // the other eleven's (0x801-0x80C), their replies to hosts 101-112 (0x865-0x870, FILL 0x565, PROCESS 0x765),
  // its own statuses (0x907 …, which carry its id), nor by these as standard, remote or >16-bit ids.
  const auto filters = controller_kernel_filters(7);
  EXPECT_TRUE(kernel_passes(filters, ext(0x807, {0x6B, 0x00, 0x32})));
  EXPECT_TRUE(kernel_passes(filters, ext(0x8FF, {0x6B, 0x00, 0x32})));
  for (std::uint32_t other = 1; other <= 12; ++other) {
    if (other != 7) {
      EXPECT_FALSE(kernel_passes(filters, ext(0x800 | other, {0x6B, 0x00, 0x32}))) << other;
    }
  }
  for (std::uint32_t host = 101; host <= 112; ++host) {
    EXPECT_FALSE(kernel_passes(filters, ext(0x800 | host, {0x07, 0x01, 0x32})));
    EXPECT_FALSE(kernel_passes(filters, ext(0x500 | host, {0x00, 0x32})));
    EXPECT_FALSE(kernel_passes(filters, ext(0x700 | host, {0x07, 0x01, 0x00, 0x1F, 0x08, 0xF7})));
  }
  for (std::uint32_t status : {9U, 14U, 15U, 16U, 27U, 58U}) {
    EXPECT_FALSE(kernel_passes(filters, ext((status << 8) | 7U, {0, 0, 0, 0, 0, 0, 0, 0}))) << status;
  }
  CanFrame standard = ext(0x007, {0x6B, 0x00, 0x32});
  standard.extended = false;
  EXPECT_FALSE(kernel_passes(filters, standard));
  EXPECT_FALSE(kernel_passes(filters, ext(0x807, {}), /*remote=*/true));
  EXPECT_FALSE(kernel_passes(filters, ext(0x10807, {0x6B, 0x00, 0x32})));
  EXPECT_FALSE(kernel_passes(filters, ext(0x1FFFF8FF, {0x6B, 0x00, 0x32})));
}

TEST(VescBadInput, CrcErrorLengthMismatchAndLostFramesAreCountedAndDropped) {
  VescDecoder dec(kController, kHost);
  auto frames = reply_frames();
  frames[2].data[3] ^= 0x01;  // one bit of i_q
  EXPECT_EQ(feed(dec, frames).back(), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.counters().crc_error, 1U);

  frames = reply_frames();
  frames.erase(frames.begin() + 2);  // a lost frame: the next fill is out of order
  EXPECT_EQ(feed(dec, frames).back(), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.counters().out_of_order, 2U);     // offsets 21 and 28 do not continue the buffer
  EXPECT_EQ(dec.counters().length_mismatch, 1U);  // the PROCESS frame finds an empty buffer

  frames = reply_frames();
  frames.erase(frames.begin() + 4);  // the last fill lost: 28 bytes against a stated 31
  EXPECT_EQ(feed(dec, frames).back(), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.counters().length_mismatch, 2U);

  // And the next complete reply decodes.
  EXPECT_EQ(feed(dec, reply_frames()).back(), VescDecoder::Event::kValues);
  EXPECT_EQ(dec.counters().replies, 1U);
}

TEST(VescBadInput, ForeignFramesAreCountedNotDecoded) {
  VescDecoder dec(kController, kHost);
  CanFrame standard = reply_frames()[0];
  standard.extended = false;  // a standard ID 0x57D is someone else's protocol
  EXPECT_EQ(dec.decode(standard), VescDecoder::Event::kNone);
  CanFrame to_other = reply_frames()[0];
  to_other.id = 0x57E;  // a fill addressed to another poller
  EXPECT_EQ(dec.decode(to_other), VescDecoder::Event::kNone);
  auto frames = reply_frames();
  frames.back().data[0] = 18;  // the reply of another controller
  EXPECT_EQ(feed(dec, frames).back(), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.decode(ext(0x912, {0, 0, 0, 0, 0, 0, 0, 0})), VescDecoder::Event::kNone);  // status of VESC 18
  EXPECT_EQ(dec.counters().foreign, 4U);
  EXPECT_EQ(dec.decode(ext(0x17D, {0, 0, 0, 0})), VescDecoder::Event::kNone);  // SET_CURRENT: not read here
  EXPECT_EQ(dec.decode(ext(0x1FFFFF7D, {0})), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.counters().unknown_packet, 2U);
  CanFrame error;
  error.error = true;
  EXPECT_EQ(dec.decode(error), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.counters().error_frames, 1U);
  EXPECT_EQ(dec.counters().replies + dec.counters().statuses, 0U);
}

/// A reply payload split as docs/can-vesc.md says (7 bytes per FILL_RX_BUFFER, then PROCESS_RX_BUFFER with
/// length and CRC), to build the malformed replies below.
std::vector<CanFrame> frames_of(const std::vector<std::uint8_t>& p) {
  std::vector<CanFrame> out;
  for (std::size_t i = 0; i < p.size(); i += 7) {
    std::vector<std::uint8_t> d = {static_cast<std::uint8_t>(i)};
    for (std::size_t k = i; k < std::min(p.size(), i + 7); ++k) d.push_back(p[k]);
    out.push_back(ext(0x57D, d));
  }
  const std::uint16_t crc = crc16_ccitt_false(p.data(), p.size(), 0);
  out.push_back(ext(0x77D, {kController, 1, static_cast<std::uint8_t>(p.size() >> 8), static_cast<std::uint8_t>(p.size()),
                            static_cast<std::uint8_t>(crc >> 8), static_cast<std::uint8_t>(crc)}));
  return out;
}

TEST(VescBadInput, ShortTrailingWrongMaskAndOtherCommandRepliesAreCounted) {
  VescDecoder dec(kController, kHost);
  std::vector<std::uint8_t> good = {0x32, 0x00, 0x18, 0x01, 0xB3, 0x01, 0x9D, 0x02, 0xA6, 0xFF, 0xFF,
                                    0xFE, 0xBF, 0x00, 0x00, 0x0A, 0xB9, 0x00, 0x00, 0x52, 0x08, 0x01,
                                    0xE2, 0xFF, 0xFF, 0xFB, 0x2E, 0x00, 0x00, 0x2E, 0x61};
  EXPECT_EQ(feed(dec, frames_of(good)).back(), VescDecoder::Event::kValues);
  auto shorter = good;
  shorter.pop_back();
  EXPECT_EQ(feed(dec, frames_of(shorter)).back(), VescDecoder::Event::kNone);
  auto longer = good;
  longer.push_back(0);
  EXPECT_EQ(feed(dec, frames_of(longer)).back(), VescDecoder::Event::kNone);
  // Mask without v_q (bit 20) and 4 bytes fewer: well formed, but not what the estimator needs.
  auto no_vq = good;
  no_vq[2] = 0x08;
  no_vq.resize(no_vq.size() - 4);
  EXPECT_EQ(feed(dec, frames_of(no_vq)).back(), VescDecoder::Event::kNone);
  auto other = good;
  other[0] = 4;  // COMM_GET_VALUES
  EXPECT_EQ(feed(dec, frames_of(other)).back(), VescDecoder::Event::kNone);
  const VescCounters& c = dec.counters();
  EXPECT_EQ(c.replies, 1U);
  EXPECT_EQ(c.short_reply, 1U);
  EXPECT_EQ(c.trailing, 1U);
  EXPECT_EQ(c.wrong_mask, 1U);
  EXPECT_EQ(c.not_values, 1U);
  EXPECT_EQ(c.crc_error, 0U);
}

TEST(VescBadInput, TooShortFramesAndOverflow) {
  VescDecoder dec(kController, kHost);
  EXPECT_EQ(dec.decode(ext(0x57D, {0x00})), VescDecoder::Event::kNone);              // fill without data
  EXPECT_EQ(dec.decode(ext(0x77D, {0x11, 0x01, 0x00})), VescDecoder::Event::kNone);  // process too short
  EXPECT_EQ(dec.decode(ext(0x87D, {0x11, 0x01})), VescDecoder::Event::kNone);        // short buffer without command
  EXPECT_EQ(dec.decode(ext(0x911, {0x00, 0x00, 0x00})), VescDecoder::Event::kNone);  // status too short
  EXPECT_EQ(dec.counters().wrong_length, 4U);
  // FILL_RX_BUFFER_LONG continues a buffer at a 16-bit offset; past the decoder's buffer it overflows.
  EXPECT_EQ(dec.decode(ext(0x57D, {0x00, 1, 2, 3, 4, 5, 6, 7})), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.decode(ext(0x67D, {0x00, 0x07, 8, 9})), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.counters().out_of_order, 0U);
  EXPECT_EQ(dec.decode(ext(0x67D, {0x00, 0x09, 1, 2, 3, 4, 5, 6})), VescDecoder::Event::kNone);
  EXPECT_EQ(dec.decode(ext(0x67D, {0x01, 0xFE, 1, 2, 3})), VescDecoder::Event::kNone);  // offset 510 ≠ fill
  EXPECT_EQ(dec.counters().out_of_order, 1U);
  // 6 bytes at offsets 0, 6, …: the one at 510 would end past the 512-byte buffer.
  for (std::size_t offset = 0; offset <= 510; offset += 6) {
    EXPECT_EQ(dec.decode(
                  ext(0x67D, {static_cast<std::uint8_t>(offset >> 8), static_cast<std::uint8_t>(offset), 1, 2, 3, 4, 5, 6})),
              VescDecoder::Event::kNone);
  }
  EXPECT_EQ(dec.counters().overflow, 1U);
  EXPECT_EQ(dec.counters().out_of_order, 1U);
}

TEST(VescBadInput, TheNativeDecoderIgnoresExtendedFramesOnASharedBus) {
  // A VESC frame whose low 11 bits equal a telemetry ID must not be read as telemetry.
  TelemetryDecoder native;
  std::array<core::DriveSample, 3> out;
  CanFrame f = ext(protocol::kFdId | (9U << 11), {0, 0, 0, 0, 0, 0, 0, 0});
  f.id = protocol::kFdId;
  EXPECT_EQ(native.decode(f, 0, out), 0U);
  EXPECT_EQ(native.counters().unknown_id, 1U);
  EXPECT_EQ(native.counters().wrong_dlc, 0U);
}

}  // namespace
}  // namespace rpem::can::vesc
