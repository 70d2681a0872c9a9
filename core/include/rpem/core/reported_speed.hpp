#pragma once
// A window's mean speed from a speed a tracking loop reports at the reads (docs/derivations.md §13,
// "Speed at the read"). VESC's erpm is its PLL's speed at the moment of the read (vedderb/bldc
// motor/foc_math.c, foc_pll_run), while the read's currents and voltages are means over the window since
// the previous read. The PLL's speed ω̂ follows the rotor's ω by ω = ω̂ + τ·dω̂/dt + (1/k_i)·d²ω̂/dt² with
// τ = k_p/k_i; integrated over the window [t_s, t],
//
//     ω̄ = mean(ω̂) + τ·(ω̂(t) − ω̂(t_s))/(t − t_s)        (+ the 1/k_i term, below VESC's resolution)
//
// and with mean(ω̂) the trapezoid of the two reads, ω̄ = ω̂_k + (ω̂_k − ω̂_{k−1})·(τ/h − ½): causal (this read
// and the previous one), exact for a ramp. The same function serves every reader of such speeds (the VESC
// Tool log's reader, rpemd's VESC source): pure and allocation-free.

#include <cmath>
#include <cstdint>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/clock.hpp"

namespace rpem::core {

/// The lag of a type-2 PLL's speed behind a speed ramp, k_p/k_i [s] (k_p in 1/s, k_i in 1/s²).
[[nodiscard]] constexpr double pll_ramp_lag_s(double kp_per_s, double ki_per_s2) noexcept { return kp_per_s / ki_per_s2; }

/// One reported speed and when it was read.
struct SpeedRead {
  std::int64_t t_ns = 0;
  double omega_el_rad_s = 0.0;
};

/// The rotor's mean speed over the window [t_start_ns, now.t_ns] from the tracker's speeds at the previous
/// read and at this one (previous.t_ns ≤ t_start_ns < now.t_ns; a window may start after the previous read
/// where another reader reset the means: the tracker's speed there is interpolated). `lag_s` is the
/// tracker's ramp lag (pll_ramp_lag_s); 0 leaves the trapezoid of an instantaneous speed. Reads at the same
/// instant give the speed as reported.
[[nodiscard]] inline double window_mean_speed_rad_s(const SpeedRead& previous, const SpeedRead& now, std::int64_t t_start_ns,
                                                    double lag_s) noexcept {
  const double between_s = to_seconds(now.t_ns - previous.t_ns);
  if (!(between_s > 0.0)) return now.omega_el_rad_s;
  const double slope = (now.omega_el_rad_s - previous.omega_el_rad_s) / between_s;  // of the tracker's speed
  // Its mean over the window (trapezoid) is ω̂ − slope·h/2; the rotor led it by lag·slope.
  return now.omega_el_rad_s - slope * (0.5 * to_seconds(now.t_ns - t_start_ns) - lag_s);
}

/// The mean speed over [start, end] from a count of the angle it travelled (a drive's step count, in rad):
/// exact but for one step at each end, so within a step over the run (docs/derivations.md §13, "The count's
/// speed at a crawl"). NaN where the run has no length.
[[nodiscard]] inline double counted_mean_speed_rad_s(double travel_start_rad, std::int64_t start_ns, double travel_end_rad,
                                                     std::int64_t end_ns) noexcept {
  const double run_s = to_seconds(end_ns - start_ns);
  return run_s > 0.0 ? (travel_end_rad - travel_start_rad) / run_s : std::nan("");
}

/// The speed a window stands for: the count's where the drive's angle is a staircase — its counted speed below
/// `staircase_below_rad_s` (a VESC in Hall mode below foc_hall_interp_erpm holds each state's angle, and its
/// PLL's speed at a read is not the window's mean) — else the reported one. 0, or no count: the reported one.
[[nodiscard]] inline double window_speed_rad_s(const AveragedSample& a, double staircase_below_rad_s) noexcept {
  return std::abs(a.omega_counted_el_rad_s) < staircase_below_rad_s ? a.omega_counted_el_rad_s : a.omega_el_rad_s;
}

}  // namespace rpem::core
