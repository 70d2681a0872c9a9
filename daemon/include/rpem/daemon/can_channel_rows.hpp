#pragma once
// Where a SocketCAN source publishes its socket's counters (can_* in diagnostics_t): one table for every
// source that reads a CAN interface (can, vesc, signal_map).

#include <array>

#include "rpem/can/socketcan.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"

namespace rpem::daemon {

inline constexpr std::array<CounterRow<can::ChannelCounters, std::uint64_t>, 6> kChannelRows{{
    {&can::ChannelCounters::kernel_drops, &rpem::diagnostics_t::can_kernel_drops},
    {&can::ChannelCounters::reopens, &rpem::diagnostics_t::can_reopens},
    {&can::ChannelCounters::error_frames, &rpem::diagnostics_t::can_error_frames},
    {&can::ChannelCounters::bus_off, &rpem::diagnostics_t::can_bus_off},
    {&can::ChannelCounters::error_passive, &rpem::diagnostics_t::can_error_passive},
    {&can::ChannelCounters::controller_overflow, &rpem::diagnostics_t::can_controller_overflow},
}};

}  // namespace rpem::daemon
