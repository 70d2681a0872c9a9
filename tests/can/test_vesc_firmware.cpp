// The emulator's protocol side (can/vesc_firmware.hpp) against frames written byte by byte from
// docs/can-vesc.md (tests/support/vesc_frames.hpp), not against our own decoder: the reply, the short
// buffer, a reply long enough for FILL_RX_BUFFER_LONG with its CRC computed bit by bit here, the status
// broadcasts, and the requests a VESC accepts.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "rpem/can/vesc_firmware.hpp"
#include "support/vesc_frames.hpp"

namespace rpem::can::vesc {
namespace {

using test::vesc_frames::ext;
using test::vesc_frames::kController;
using test::vesc_frames::kHost;  // the poller (rpemd)

void expect_same(const std::vector<CanFrame>& got, const std::vector<CanFrame>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    EXPECT_TRUE(got[k].extended);
    EXPECT_EQ(got[k].id, want[k].id);
    ASSERT_EQ(got[k].len, want[k].len);
    for (int b = 0; b < want[k].len; ++b) EXPECT_EQ(got[k].data[b], want[k].data[b]) << "byte " << b;
  }
}

std::vector<CanFrame> split(std::span<const std::uint8_t> payload, std::uint8_t to, std::uint8_t from) {
  std::vector<CanFrame> out(buffer_frame_count(payload.size()));
  out.resize(buffer_frames(to, from, 1, payload, out));
  return out;
}

/// CRC-16/XMODEM bit by bit (polynomial 0x1021, initial 0), independent of the library's table.
std::uint16_t crc_xmodem(const std::vector<std::uint8_t>& d) {
  std::uint16_t crc = 0;
  for (std::uint8_t byte : d) {
    crc ^= static_cast<std::uint16_t>(byte << 8);
    for (int k = 0; k < 8; ++k)
      crc = (crc & 0x8000) ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021) : static_cast<std::uint16_t>(crc << 1);
  }
  return crc;
}

TEST(VescFirmware, TheReplyIsTheDocumentedBytes) {
  Values v;
  v.temp_fet_C = 41.3;
  v.temp_motor_C = 67.8;
  v.i_d_A = -3.21;
  v.i_q_A = 27.45;
  v.erpm = 21000.0;
  v.v_in_V = 48.2;
  v.v_d_V = -1.234;
  v.v_q_V = 11.873;
  std::array<std::uint8_t, kMaxValuesPayload> payload{};
  const std::size_t len = encode_values(v, kEstimatorMask, payload);
  EXPECT_EQ(len, 31U);
  expect_same(split({payload.data(), len}, kHost, kController), test::vesc_frames::reply_frames());
}

TEST(VescFirmware, ShortRepliesTravelInOneShortBuffer) {
  Values v;
  v.fault = 3;
  std::array<std::uint8_t, kMaxValuesPayload> payload{};
  const std::size_t len = encode_values(v, bit(kFault), payload);
  ASSERT_EQ(len, 6U);
  expect_same(split({payload.data(), len}, kHost, kController),
              {ext(0x87D, {0x11, 0x01, 0x32, 0x00, 0x00, 0x80, 0x00, 0x03})});
}

TEST(VescFirmware, LongBuffersSwitchToTwoByteOffsetsPastByte255) {
  // comm_can_send_buffer: FILL_RX_BUFFER at offsets 0, 7, …, 252 (37 frames), FILL_RX_BUFFER_LONG from 259.
  std::vector<std::uint8_t> p(300);
  for (std::size_t k = 0; k < p.size(); ++k) p[k] = static_cast<std::uint8_t>(k * 7 + 1);
  const auto frames = split(p, kHost, kController);
  ASSERT_EQ(frames.size(), 37U + 7U + 1U);  // 259 bytes in 37 short fills, 41 in 7 long ones, then process
  EXPECT_EQ(frames[36].id, 0x57DU);
  EXPECT_EQ(frames[36].data[0], 252);
  EXPECT_EQ(frames[36].len, 8);
  EXPECT_EQ(frames[37].id, 0x67DU);
  EXPECT_EQ(frames[37].data[0], 0x01);  // 259 = 0x0103
  EXPECT_EQ(frames[37].data[1], 0x03);
  EXPECT_EQ(frames[37].data[2], p[259]);
  EXPECT_EQ(frames[43].len, 2 + 5);  // 295..299
  const std::uint16_t crc = crc_xmodem(p);
  expect_same(
      {frames.back()},
      {ext(0x77D, {kController, 0x01, 0x01, 0x2C, static_cast<std::uint8_t>(crc >> 8), static_cast<std::uint8_t>(crc)})});
  EXPECT_EQ(crc_xmodem({'1', '2', '3', '4', '5', '6', '7', '8', '9'}), 0x31C3);  // the check value, for the helper
}

TEST(VescFirmware, StatusFramesAreTheDocumentedBytes) {
  Status s1;
  s1.controller_id = kController;
  s1.number = 1;
  s1.erpm = -1500.0;
  s1.current_A = 12.3;
  s1.duty = 0.456;
  expect_same({status_frame(s1)}, {test::vesc_frames::status1()});
  Status s4;
  s4.controller_id = kController;
  s4.number = 4;
  s4.temp_fet_C = 35.5;
  s4.temp_motor_C = 80.1;
  s4.current_in_A = 5.5;
  s4.pid_pos_deg = 90.0;
  expect_same({status_frame(s4)}, {test::vesc_frames::status4()});
  Status s5;
  s5.controller_id = kController;
  s5.number = 5;
  s5.tachometer = 123456;
  s5.v_in_V = 50.4;
  expect_same({status_frame(s5)}, {test::vesc_frames::status5()});
}

TEST(VescFirmware, FloatsConvertAsTheCortexM4Casts) {
  // Truncation toward zero, NaN to 0 (an average of zero cycles), saturation at the int32 range.
  Values v;
  v.i_d_A = -0.019;  // −1.9 → −1
  v.i_q_A = std::nan("");
  v.erpm = 1e12;
  std::array<std::uint8_t, kMaxValuesPayload> p{};
  ASSERT_EQ(encode_values(v, bit(kId) | bit(kIq) | bit(kRpm), p), 17U);
  const std::vector<std::uint8_t> want = {0x32, 0, 0, 0, 0xB0, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0, 0, 0x7F, 0xFF, 0xFF, 0xFF};
  EXPECT_EQ(std::vector<std::uint8_t>(p.begin(), p.begin() + 17), want);
}

TEST(VescFirmware, AcceptsShortBufferRequestsToItselfOrEveryone) {
  // The documented poll: ID 0x811, 7D 00 32 00 18 01 B3.
  const auto r = parse_request(ext(0x811, {0x7D, 0x00, 0x32, 0x00, 0x18, 0x01, 0xB3}), kController);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->sender, 0x7D);
  EXPECT_EQ(r->commands_send, 0);
  EXPECT_EQ(r->command, kCommGetValuesSelective);
  ASSERT_TRUE(r->has_mask);
  EXPECT_EQ(r->mask, 0x001801B3U);
  EXPECT_TRUE(parse_request(ext(0x8FF, {0x7D, 0x00, 0x32, 0, 0, 0, 1}), kController).has_value());   // 255
  EXPECT_FALSE(parse_request(ext(0x812, {0x7D, 0x00, 0x32, 0, 0, 0, 1}), kController).has_value());  // VESC 18
  EXPECT_FALSE(parse_request(ext(0x511, {0x00, 0x32}), kController).has_value());                    // a fill, not a request
  CanFrame standard = ext(0x011, {0x7D, 0x00, 0x32});
  standard.extended = false;
  EXPECT_FALSE(parse_request(standard, kController).has_value());
  EXPECT_FALSE(parse_request(ext(0x811, {0x7D, 0x00, 0x32, 0}), kController)->has_mask);  // truncated mask
}

}  // namespace
}  // namespace rpem::can::vesc
