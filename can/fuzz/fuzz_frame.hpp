#pragma once
// The frame record the CAN fuzz targets share: [id, 4 bytes little endian][flags: bit0 extended,
// bit1 error][len][len bytes, at most 8].
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "rpem/can/frame.hpp"

namespace rpem::can::fuzz {

/// Reads one record at `at` (advanced past it); false when fewer than its header's bytes remain.
inline bool read_frame(const std::uint8_t* data, std::size_t size, std::size_t& at, CanFrame& f) noexcept {
  if (at + 6 > size) return false;
  f = CanFrame{};
  f.id = static_cast<std::uint32_t>(data[at]) | (static_cast<std::uint32_t>(data[at + 1]) << 8) |
         (static_cast<std::uint32_t>(data[at + 2]) << 16) | (static_cast<std::uint32_t>(data[at + 3]) << 24);
  f.extended = data[at + 4] & 1;
  f.error = data[at + 4] & 2;
  f.len = static_cast<std::uint8_t>(std::min<std::size_t>(data[at + 5], 8));
  at += 6;
  const std::size_t n = std::min<std::size_t>(f.len, size - at);
  std::copy_n(data + at, n, f.data.begin());
  at += n;
  return true;
}

}  // namespace rpem::can::fuzz
