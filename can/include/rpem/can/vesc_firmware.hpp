#pragma once
// VESC (vedderb/bldc) over CAN, the firmware's side: what a VESC sends, for the emulator of `rpem sim
// --vesc`. The receiver's side is vesc.hpp; both follow docs/can-vesc.md, which names the file and function
// of VESC's firmware behind every layout:
//   - a request arrives as PROCESS_SHORT_BUFFER to the controller id or 255 (comm_can.c, decode_msg);
//   - the COMM_GET_VALUES_SELECTIVE reply is [50][mask][fields in bit order] (commands.c,
//     commands_process_packet) with VESC's scalings (buffer.c, buffer_append_float16/32);
//   - it travels as comm_can_send_buffer splits it: one PROCESS_SHORT_BUFFER up to 6 bytes, else
//     FILL_RX_BUFFER / FILL_RX_BUFFER_LONG frames and PROCESS_RX_BUFFER with the length and crc16;
//   - status broadcasts 1–6 (comm_can_send_status1…6).
// Numbers convert as the Cortex-M4 does a C cast of a float: truncation toward zero, saturation at the
// int32 range and NaN to 0 (VCVT); an int16 field keeps the low 16 bits of that int32. So the average of
// zero control cycles (0/0 in mc_interface_read_reset_avg_*) goes out as 0. Pure: no I/O, no allocation.

#include <cstdint>
#include <optional>
#include <span>

#include "rpem/can/frame.hpp"
#include "rpem/can/vesc.hpp"

namespace rpem::can::vesc {

/// A command a VESC received in one PROCESS_SHORT_BUFFER frame.
struct Request {
  std::uint8_t sender = 0;         ///< where the reply goes (rx_buffer_last_id)
  std::uint8_t commands_send = 0;  ///< 0: process and reply
  std::uint8_t command = 0;        ///< COMM_PACKET_ID
  std::uint32_t mask = 0;          ///< COMM_GET_VALUES_SELECTIVE only
  bool has_mask = false;
};

/// The request in `f` if it is a PROCESS_SHORT_BUFFER addressed to `controller_id` or to 255.
[[nodiscard]] std::optional<Request> parse_request(const CanFrame& f, std::uint8_t controller_id) noexcept;

/// The reply payload [50][mask][fields] of `v` for `mask` (bits ≥ kFieldCount are ignored, as the
/// firmware ignores them). Returns its length; `out` must hold kMaxValuesPayload bytes.
inline constexpr std::size_t kMaxValuesPayload = 64;
[[nodiscard]] std::size_t encode_values(const Values& v, std::uint32_t mask, std::span<std::uint8_t> out) noexcept;

/// A number as a host reads it after the firmware sent it: value·scale in float, cast as the Cortex-M4 casts
/// (buffer_append_float32 / _float16), then the integer divided by the scale (the receiver's buffer_get_float32
/// / 16, VESC Tool's VByteArray::vbPopFrontDouble32 / 16).
[[nodiscard]] double wire_float32(double value, float scale) noexcept;
[[nodiscard]] double wire_float16(double value, float scale) noexcept;

/// comm_can_send_buffer(to_id, payload, send): the frames a VESC with id `from_id` sends. Returns how
/// many it wrote to `out` (0 if `out` is too small).
[[nodiscard]] std::size_t buffer_frames(std::uint8_t to_id, std::uint8_t from_id, std::uint8_t send,
                                        std::span<const std::uint8_t> payload, std::span<CanFrame> out) noexcept;
/// Frames a reply of `payload_len` bytes takes (for sizing `out`).
[[nodiscard]] constexpr std::size_t buffer_frame_count(std::size_t payload_len) noexcept {
  if (payload_len <= 6) return 1;
  const std::size_t short_fills = payload_len <= 259 ? (payload_len + 6) / 7 : 37;
  const std::size_t long_fills = payload_len <= 259 ? 0 : (payload_len - 259 + 5) / 6;
  return short_fills + long_fills + 1;
}

/// Status broadcast `s.number` (1–6) from `s.controller_id`.
[[nodiscard]] CanFrame status_frame(const Status& s) noexcept;

}  // namespace rpem::can::vesc
