#pragma once
// Bytes received from the network into one lcm-gen message, never an exception: lcm-gen's decoders return a
// negative status for short input but throw from std::string for a string length field below 1 (LCM 1.3.1's
// generated `__string_decode_array`: `assign(.., len - 1)`), and LCM's typed subscription decodes before the
// handler runs, outside any try. So a receiver subscribes to the raw bytes and decodes with this.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <span>

namespace rpem::schema {

/// Decodes `encoded` into `out` if it is exactly one message of type T (no byte short, none left over).
template <class T>
[[nodiscard]] bool decode_exactly(std::span<const std::uint8_t> encoded, T& out) noexcept {
  if (encoded.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) return false;
  const int size = static_cast<int>(encoded.size());
  try {
    return out.decode(encoded.data(), 0, size) == size;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace rpem::schema
