#pragma once
// VESC frames written byte by byte from docs/can-vesc.md (which cites vedderb/bldc: comm/comm_can.c
// comm_can_send_buffer, decode_msg; comm/commands.c commands_process_packet, case
// COMM_GET_VALUES_SELECTIVE; util/buffer.c; util/crc.c crc16), not with rpem's encoder. The reply's CRC was
// computed with Python's binascii.crc_hqx(payload, 0) (CRC-16/XMODEM). Shared by the decoder's
// conformance tests (tests/can/test_vesc.cpp), the rpemd source's (tests/daemon/test_vesc_poller.cpp) and
// the emulator's (tests/can/test_vesc_firmware.cpp, tests/sim/test_vesc_emulator.cpp).

#include <algorithm>
#include <cstdint>
#include <vector>

#include "rpem/can/frame.hpp"

namespace rpem::test::vesc_frames {

inline constexpr std::uint8_t kController = 17;  // the VESC
inline constexpr std::uint8_t kHost = 0x7D;      // the poller (rpemd)

inline can::CanFrame ext(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  can::CanFrame f;
  f.extended = true;
  f.id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data.begin());
  return f;
}

/// The reply to a poll with the estimator's mask 0x001801B3: T_fet 41.3 °C, T_motor 67.8 °C, i_d −3.21 A,
/// i_q 27.45 A, 21000 ERPM, V_in 48.2 V, v_d −1.234 V, v_q 11.873 V — 31 bytes in five FILL_RX_BUFFER
/// frames (ID 0x57D: host id 0x7D | 5 << 8) and PROCESS_RX_BUFFER (0x77D) from controller 17, CRC 0x08F7.
inline std::vector<can::CanFrame> reply_frames() {
  return {ext(0x57D, {0x00, 0x32, 0x00, 0x18, 0x01, 0xB3, 0x01, 0x9D}),
          ext(0x57D, {0x07, 0x02, 0xA6, 0xFF, 0xFF, 0xFE, 0xBF, 0x00}),
          ext(0x57D, {0x0E, 0x00, 0x0A, 0xB9, 0x00, 0x00, 0x52, 0x08}),
          ext(0x57D, {0x15, 0x01, 0xE2, 0xFF, 0xFF, 0xFB, 0x2E, 0x00}),
          ext(0x57D, {0x1C, 0x00, 0x2E, 0x61}),
          ext(0x77D, {0x11, 0x01, 0x00, 0x1F, 0x08, 0xF7})};
}

/// The same reply with 22000 ERPM (bytes 17–20 of the payload 0x000055F0), CRC 0x900A.
inline std::vector<can::CanFrame> reply_frames_22000_erpm() {
  return {ext(0x57D, {0x00, 0x32, 0x00, 0x18, 0x01, 0xB3, 0x01, 0x9D}),
          ext(0x57D, {0x07, 0x02, 0xA6, 0xFF, 0xFF, 0xFE, 0xBF, 0x00}),
          ext(0x57D, {0x0E, 0x00, 0x0A, 0xB9, 0x00, 0x00, 0x55, 0xF0}),
          ext(0x57D, {0x15, 0x01, 0xE2, 0xFF, 0xFF, 0xFB, 0x2E, 0x00}),
          ext(0x57D, {0x1C, 0x00, 0x2E, 0x61}),
          ext(0x77D, {0x11, 0x01, 0x00, 0x1F, 0x90, 0x0A})};
}

/// The same reply from a VESC without a reading of its motor sensor: T_motor −100.0 °C, the value the firmware
/// filters in for none (vedderb/bldc motor/mc_interface.c, update_override_limits), as float16 ×10: −1000 = 0xFC18
/// (bytes 7–8 of the payload), CRC 0x74AD.
inline std::vector<can::CanFrame> reply_frames_no_motor_reading() {
  return {ext(0x57D, {0x00, 0x32, 0x00, 0x18, 0x01, 0xB3, 0x01, 0x9D}),
          ext(0x57D, {0x07, 0xFC, 0x18, 0xFF, 0xFF, 0xFE, 0xBF, 0x00}),
          ext(0x57D, {0x0E, 0x00, 0x0A, 0xB9, 0x00, 0x00, 0x52, 0x08}),
          ext(0x57D, {0x15, 0x01, 0xE2, 0xFF, 0xFF, 0xFB, 0x2E, 0x00}),
          ext(0x57D, {0x1C, 0x00, 0x2E, 0x61}),
          ext(0x77D, {0x11, 0x01, 0x00, 0x1F, 0x74, 0xAD})};
}

/// STATUS (9) from VESC 17: ERPM −1500, current 12.3 A, duty 0.456.
inline can::CanFrame status1() { return ext(0x911, {0xFF, 0xFF, 0xFA, 0x24, 0x00, 0x7B, 0x01, 0xC8}); }
/// STATUS_4 (16): T_fet 35.5 °C, T_motor 80.1 °C, input current 5.5 A, PID position 90°.
inline can::CanFrame status4() { return ext(0x1011, {0x01, 0x63, 0x03, 0x21, 0x00, 0x37, 0x11, 0x94}); }
/// STATUS_5 (27): tachometer 123456, V_in 50.4 V, reserved.
inline can::CanFrame status5() { return ext(0x1B11, {0x00, 0x01, 0xE2, 0x40, 0x01, 0xF8, 0x00, 0x00}); }

}  // namespace rpem::test::vesc_frames
