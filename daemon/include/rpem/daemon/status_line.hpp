#pragma once
// rpemd's status line on stdout, one per status_interval_s (docs/rpemd.md, "The status line"): the state, the
// speed, each parameter with its mark and the temperature derived from it; with a thermal network both fused
// temperatures with their σ and how each stands (observed now, or predicted since its last observation); the
// simulated drive's truth; a VESC source's poll counters. Printed by the publisher thread, never the loop.

#include <string>

#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/source.hpp"

namespace rpem::daemon {

/// The line for the newest estimate and the source's newest report, without its newline.
[[nodiscard]] std::string status_line(const EstimateReport& r, const SourceReport& source);

}  // namespace rpem::daemon
