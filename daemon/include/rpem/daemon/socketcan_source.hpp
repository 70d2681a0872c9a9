#pragma once
// What every source that reads a SocketCAN interface (can, vesc, signal_map) shares: its `interface`
// option, a frame's receive time, and its report — the decoder's rows beside the socket's counters
// (can_* in diagnostics_t).

#include <array>
#include <cstdint>
#include <string>

#include "rpem/can/socketcan.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"
#include "rpem/daemon/source.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::daemon {

inline constexpr std::array<CounterRow<can::ChannelCounters, std::uint64_t>, 7> kChannelRows{{
    {&can::ChannelCounters::kernel_drops, &rpem::diagnostics_t::can_kernel_drops},
    {&can::ChannelCounters::reopens, &rpem::diagnostics_t::can_reopens},
    {&can::ChannelCounters::open_failures, &rpem::diagnostics_t::can_open_failures},
    {&can::ChannelCounters::error_frames, &rpem::diagnostics_t::can_error_frames},
    {&can::ChannelCounters::bus_off, &rpem::diagnostics_t::can_bus_off},
    {&can::ChannelCounters::error_passive, &rpem::diagnostics_t::can_error_passive},
    {&can::ChannelCounters::controller_overflow, &rpem::diagnostics_t::can_controller_overflow},
}};

/// The section's `interface`: a SocketCAN interface name.
[[nodiscard]] inline std::string parse_interface(io::YamlMap& section) {
  std::string name = section.text("interface");
  if (name.empty() || name.size() > 15) section.fail("interface", "not an interface name");
  return name;
}

using can::receive_time_ns;

/// Says in the journal when the interface cannot be opened or is lost, and when it is open again: once per change,
/// not once per retry (can_open_failures counts the retries). The source thread's, outside the loop.
class ChannelNotices {
 public:
  void check(const can::SocketCanChannel& channel, const std::string& interface);

 private:
  std::string said_;  ///< the problem last said; empty: none since it was last open
};

/// Sends the source's report when due: `fill(rows)` adds the decoder's rows, the socket's are added here.
template <class Fill>
void report_when_due(SourceOutput& out, const can::SocketCanChannel& channel, ChannelNotices& notices,
                     const std::string& interface, Fill&& fill) {
  const std::int64_t now = core::now_ns(CLOCK_MONOTONIC);
  if (!out.report_due(now)) return;
  notices.check(channel, interface);
  SourceReport r;
  fill(r.rows);
  r.rows.set_all(kChannelRows, channel.counters());
  out.report(r, now);
}

}  // namespace rpem::daemon
