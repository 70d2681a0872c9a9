#pragma once
// A SocketCAN kernel receive filter in portable terms (linux/can.h, struct can_filter; the flag values are
// the kernel's ABI, checked in socketcan.cpp): a frame passes when (its can_id & mask) == (id & mask), its
// can_id carrying kEffFlag for a 29-bit id and kRtrFlag for a remote frame.

#include <cstdint>

namespace rpem::can {

struct KernelFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
};
inline constexpr std::uint32_t kEffFlag = 0x80000000U;  ///< CAN_EFF_FLAG
inline constexpr std::uint32_t kRtrFlag = 0x40000000U;  ///< CAN_RTR_FLAG
inline constexpr std::uint32_t kEffMask = 0x1FFFFFFFU;  ///< CAN_EFF_MASK

}  // namespace rpem::can
