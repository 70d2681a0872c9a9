#pragma once
// A CAN or CAN FD frame, independent of the Linux headers (the codec is pure and portable; only
// socketcan.cpp touches <linux/can.h>).

#include <array>
#include <cstdint>

namespace rpem::can {

struct CanFrame {
  std::uint32_t id = 0;   ///< 11-bit standard identifier, or 29-bit where `extended`
  bool extended = false;  ///< 29-bit extended identifier (SocketCAN CAN_EFF_FLAG), e.g. VESC's
  std::uint8_t len = 0;   ///< payload bytes: 0–8 (classic) or 0–64 (FD)
  bool fd = false;        ///< CAN FD frame
  bool error = false;     ///< an error frame reported by the controller (SocketCAN CAN_ERR_FLAG)
  std::array<std::uint8_t, 64> data{};
};

}  // namespace rpem::can
