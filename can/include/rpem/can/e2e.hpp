#pragma once
// End-to-end protection in the style of AUTOSAR E2E profile 5: a CRC-16 (CCITT-FALSE: polynomial
// 0x1021, initial value 0xFFFF, no reflection, no final XOR) at payload bytes 0–1 (little endian),
// an 8-bit alive counter at byte 2, and the CRC computed over bytes 2…len−1 followed by the 16-bit
// Data ID (low byte, then high byte), so a frame with the right layout but the wrong ID fails.

#include <cstddef>
#include <cstdint>

#include "rpem/can/frame.hpp"

namespace rpem::can {

[[nodiscard]] std::uint16_t crc16_ccitt_false(const std::uint8_t* data, std::size_t len,
                                              std::uint16_t crc = 0xFFFF) noexcept;

/// Writes the counter and the CRC into frame.data[0..2].
void e2e_protect(CanFrame& frame, std::uint16_t data_id, std::uint8_t counter) noexcept;

/// True if the CRC matches the frame's contents and Data ID.
[[nodiscard]] bool e2e_check(const CanFrame& frame, std::uint16_t data_id) noexcept;

[[nodiscard]] inline std::uint8_t e2e_counter(const CanFrame& frame) noexcept { return frame.data[2]; }

}  // namespace rpem::can
