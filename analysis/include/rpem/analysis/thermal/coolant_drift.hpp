#pragma once
// How fast a coolant moves between its readings (docs/derivations.md §14, eq. 14.29b): the intensity q_c of the
// random walk the filter takes an unread coolant to be (core::ThermalFilterConfig::coolant_drift_K2_per_s).
//
// The coolant's structure function D(s) = E[(T_c(t + s) − T_c(t))²], measured on the steps that carry a coolant
// reading, at lags s of one step and doubling up to a 32nd of the longest session's training steps (each session on
// its own; every D(s) a mean over at least 32 independent moves).
// What no lag removes, D_floor = min_s D(s), is at most the readings' own noise (2σ² where D(s) = q·s + 2σ²); the
// coolant's move is what lies above it by more than its sampling error ε_s (two standard errors of D(s) − D_floor),
// and
//   q_c = max_s (D(s) − D_floor − ε_s) / s
// the smallest walk whose variance q_c·s bounds the measured move at every lag: a walk's D grows as s, a bounded
// move (a controlled loop) levels off, so the bound holds a silence of any length, conservatively for a long one.
// Without ε_s the sampling error of the shortest lags, divided by their few seconds, would read as a walk.

#include <cstddef>
#include <string>

#include "rpem/analysis/thermal/thermal_record.hpp"

namespace rpem::analysis {

struct CoolantDrift {
  double q_K2_per_s = 0.0;  ///< 0: no lag to measure (no coolant readings, or too few steps)
  double floor_K2 = 0.0;    ///< D_floor
  double at_lag_s = 0.0;    ///< the lag that sets q_c
  double shortest_lag_s = 0.0, longest_lag_s = 0.0;
  int lags = 0;  ///< lags measured
};

/// q_c from the coolant readings of `r`'s first `training` steps.
[[nodiscard]] CoolantDrift coolant_drift(const ThermalRecord& r, std::size_t training);

/// What the fit found, for its report and the terminal: q_c, how it was set, and the σ it gives the coolant after ten
/// minutes unread; or why it is 0.
[[nodiscard]] std::string coolant_drift_sentence(const CoolantDrift& d);

}  // namespace rpem::analysis
