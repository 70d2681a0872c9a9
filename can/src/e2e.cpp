#include "rpem/can/e2e.hpp"

namespace rpem::can {
namespace {

constexpr std::array<std::uint16_t, 256> make_table() {
  std::array<std::uint16_t, 256> t{};
  for (unsigned b = 0; b < 256; ++b) {
    auto crc = static_cast<std::uint16_t>(b << 8);
    for (int k = 0; k < 8; ++k) crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
    t[b] = crc;
  }
  return t;
}
constexpr auto kTable = make_table();

std::uint16_t frame_crc(const CanFrame& f, std::uint16_t data_id) noexcept {
  std::uint16_t crc = crc16_ccitt_false(f.data.data() + 2, f.len > 2 ? f.len - 2U : 0U);
  const std::uint8_t id[2] = {static_cast<std::uint8_t>(data_id & 0xFF), static_cast<std::uint8_t>(data_id >> 8)};
  return crc16_ccitt_false(id, 2, crc);
}

}  // namespace

std::uint16_t crc16_ccitt_false(const std::uint8_t* data, std::size_t len, std::uint16_t crc) noexcept {
  for (std::size_t k = 0; k < len; ++k) {
    crc = static_cast<std::uint16_t>((crc << 8) ^ kTable[((crc >> 8) ^ data[k]) & 0xFF]);
  }
  return crc;
}

void e2e_protect(CanFrame& frame, std::uint16_t data_id, std::uint8_t counter) noexcept {
  frame.data[2] = counter;
  const std::uint16_t crc = frame_crc(frame, data_id);
  frame.data[0] = static_cast<std::uint8_t>(crc & 0xFF);
  frame.data[1] = static_cast<std::uint8_t>(crc >> 8);
}

bool e2e_check(const CanFrame& frame, std::uint16_t data_id) noexcept {
  if (frame.len < 3) return false;
  const auto stored = static_cast<std::uint16_t>(frame.data[0] | (frame.data[1] << 8));
  return stored == frame_crc(frame, data_id);
}

}  // namespace rpem::can
