#pragma once
// A restart of the fusion on a machine that may be hot (docs/thermal.md, "A restart"): the filter's node
// temperatures and their covariance as last saved, carried over the time nothing was measured. rpemd sits beside
// the drive, so its restart says nothing of the load in between: the drive may have stopped or run on. Both are
// predicted by the network over the gap — no loss (the machine cools to the coolant) and the last load held —
// and the start is their even mixture, moment-matched (docs/derivations.md §14, eq. 14.26):
//
//   m = (a + b)/2,   P = (P_a + P_b)/2 + (b − a)(b − a)ᵀ/4
//
// so its 2σ band covers both ends. The disturbances and the laws' calibration states start again from their
// priors, as at any start. Not real-time: once, before the loop runs.

#include "rpem/core/thermal_filter.hpp"

namespace rpem::core {

/// What a restart needs of the filter: its node temperatures, their covariance and the load they were under.
struct ThermalSnapshot {
  int nodes = 0;  ///< the network's; 0: no state (the filter had not started)
  int winding = 0, magnet = 1;
  ThermalVec t_C = ThermalVec::Zero();
  ThermalMat p_K2 = ThermalMat::Zero();
  ThermalLoad load;  ///< the newest step's (its dt_s unused)
};

/// Whether a snapshot is one of this network (the same nodes, winding and magnet): a changed network starts afresh.
[[nodiscard]] bool fits_network(const ThermalSnapshot& s, const ThermalNetwork& n) noexcept;

/// Where a network whose state was `s` stands `gap_s` later under an unknown load: the mixture above, each
/// prediction in steps of at most `step_s` (and at most 1 000 of them: the transition is exact for a held load,
/// only the noise's integration depends on the step). `s` must fit the filter's network.
[[nodiscard]] ThermalSnapshot across_unknown_load(const ThermalFilterConfig& c, const ThermalSnapshot& s, double gap_s,
                                                  double step_s) noexcept;

}  // namespace rpem::core
