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
#include <cstddef>
#include <cstdint>
#include <span>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/clock.hpp"

namespace rpem::core {

/// The lag of a type-2 PLL's speed behind a speed ramp, k_p/k_i [s] (k_p in 1/s, k_i in 1/s²).
[[nodiscard]] constexpr double pll_ramp_lag_s(double kp_per_s, double ki_per_s2) noexcept { return kp_per_s / ki_per_s2; }

/// A type-2 PLL's gains (VESC: foc_pll_kp, foc_pll_ki); zero: the speed is not a tracker's.
struct PllGains {
  double kp_per_s = 0.0;
  double ki_per_s2 = 0.0;
  [[nodiscard]] constexpr bool given() const noexcept { return kp_per_s > 0.0 && ki_per_s2 > 0.0; }
  /// pll_ramp_lag_s, or 0 (the speed is the window's own: the rebuild leaves the trapezoid).
  [[nodiscard]] constexpr double ramp_lag_s() const noexcept { return given() ? pll_ramp_lag_s(kp_per_s, ki_per_s2) : 0.0; }
};

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

/// The larger |speed| the tracker reported at a window's two reads [rad/s]: what the window is known to have passed
/// through beside its mean (AveragedSample::omega_el_at_reads_max_rad_s; docs/derivations.md §13, "A stall's rocking").
/// A NaN read is left out (fmax).
[[nodiscard]] inline double reads_speed_max_rad_s(const SpeedRead& previous, const SpeedRead& now) noexcept {
  return std::fmax(std::fabs(previous.omega_el_rad_s), std::fabs(now.omega_el_rad_s));
}

/// The tracker's mean acceleration over the window ending at `now` less that over the window before it, from its
/// speeds at three consecutive reads [rad/s²]; 0 where two reads share an instant.
[[nodiscard]] inline double read_accel_change_rad_s2(const SpeedRead& earlier, const SpeedRead& previous,
                                                     const SpeedRead& now) noexcept {
  const double before_s = to_seconds(previous.t_ns - earlier.t_ns), after_s = to_seconds(now.t_ns - previous.t_ns);
  if (!(before_s > 0.0 && after_s > 0.0)) return 0.0;
  return (now.omega_el_rad_s - previous.omega_el_rad_s) / after_s -
         (previous.omega_el_rad_s - earlier.omega_el_rad_s) / before_s;
}

/// window_mean_speed_rad_s's error over a window of `window_s` across which the tracker's acceleration changed by
/// `accel_change_rad_s2` (read_accel_change_rad_s2; docs/derivations.md §13, "Speed at the read", "… where the
/// acceleration changes"): the trapezoid's h²/12·|ω̂''| with |ω̂''| up to |Δa|·g_max, g_max the peak of the PLL's
/// impulse response k_i/(s² + k_p·s + k_i), and the dropped (ω̂'(t) − ω̂'(t_s))/(k_i·h). 0 where the gains are
/// not given (the speed is the window's own mean).
[[nodiscard]] double window_mean_speed_error_rad_s(const PllGains& pll, double accel_change_rad_s2,
                                                   double window_s) noexcept;

/// How many reads' changes of acceleration a window's noise of them is the median of (centred on the window in a log,
/// the latest in rpemd): robust to 8 of them being the rotor's own (a stop's 2–3), as a noise median's warm-up.
inline constexpr std::size_t kAccelChangeRunReads = 17;

/// The noise σ of the changes of acceleration a run of reads shows (reads that jitter, a sensorless observer's PLL at
/// a crawl): 1.4826·median|Δâ|, a normal's; NaNs left out; 0 with fewer than three. Reorders `changes`; no allocation.
[[nodiscard]] double accel_change_sigma_rad_s2(std::span<double> changes) noexcept;

/// One read of a drive's count of the angle it travelled (VESC's tachometer: six steps per electrical turn).
struct CountRead {
  std::int64_t t_ns = 0;
  double travel_el_rad = 0.0;
};

/// The longest time on each side of a window over which its speed is counted (docs/derivations.md §13, "The count's
/// speed over a grown run"): what rpemd's VESC source holds each window back by when it counts.
inline constexpr double kCountRunSideMaxS = 0.25;

/// The counted mean speed of the window between reads `s` and `e` (s < e) of `reads` (random access: size(),
/// [j].t_ns, [j].travel_el_rad; times increasing) — docs/derivations.md §13, "The count's speed at a crawl" and
/// "… over a grown run". The run of reads a = s − m … b = e + m centred on the window: m = 1 (or the reads there
/// are), grown while both sides stay within `side_max_ns` and the speeds counted on the two sides agree within
/// their resolutions. A count is within 2·step of the rotor's travel (one step for where each end falls inside its
/// step, one for the angle in use leading or lagging the rotor by up to half a step at each end, a Hall state's
/// centre), so a side of length s_i resolves 2·step/s_i; sides that differ by more saw the speed change, and the
/// run stops before them. Symmetric, the run's mean is the window's under a constant acceleration. NaN: no run.
template <class Reads>
[[nodiscard]] double grown_count_speed_rad_s(const Reads& reads, std::size_t s, std::size_t e, double step_rad,
                                             std::int64_t side_max_ns) noexcept {
  const std::size_t n = reads.size();
  if (!(s < e && e < n)) return std::nan("");
  const auto rate = [&](std::size_t a, std::size_t b) {
    const double run_s = to_seconds(reads[b].t_ns - reads[a].t_ns);
    return run_s > 0.0 ? (reads[b].travel_el_rad - reads[a].travel_el_rad) / run_s : std::nan("");
  };
  std::size_t a = s > 0 ? s - 1 : s, b = e + 1 < n ? e + 1 : e;
  for (std::size_t m = 2; m <= s && e + m < n; ++m) {
    const std::int64_t left_ns = reads[s].t_ns - reads[s - m].t_ns, right_ns = reads[e + m].t_ns - reads[e].t_ns;
    if (left_ns > side_max_ns || right_ns > side_max_ns || left_ns <= 0 || right_ns <= 0) break;
    const double resolution = 2.0 * step_rad * (1.0 / to_seconds(left_ns) + 1.0 / to_seconds(right_ns));
    if (std::abs(rate(s - m, s) - rate(e, e + m)) > resolution) break;
    a = s - m;
    b = e + m;
  }
  return rate(a, b);
}

/// Whether a window stands for the count's speed: the drive's angle is a staircase there — its counted speed below
/// `staircase_below_rad_s` (a VESC in Hall mode below foc_hall_interp_erpm holds each state's angle, and its
/// PLL's speed at a read is not the window's mean). 0, or no count (NaN): never.
[[nodiscard]] inline bool counted_speed_taken(const AveragedSample& a, double staircase_below_rad_s) noexcept {
  return std::abs(a.omega_counted_el_rad_s) < staircase_below_rad_s;
}

/// The speed a window stands for: the count's where counted_speed_taken, else the reported one.
[[nodiscard]] inline double window_speed_rad_s(const AveragedSample& a, double staircase_below_rad_s) noexcept {
  return counted_speed_taken(a, staircase_below_rad_s) ? a.omega_counted_el_rad_s : a.omega_el_rad_s;
}

/// The error of window_speed_rad_s its reader states, and that error's noise: the reported speed's
/// (AveragedSample::omega_el_error_rad_s, omega_el_error_noise_rad_s), none where the count's is taken.
struct SpeedError {
  double error_rad_s = 0.0;
  double noise_rad_s = 0.0;
};
[[nodiscard]] inline SpeedError window_speed_error(const AveragedSample& a, double staircase_below_rad_s) noexcept {
  if (counted_speed_taken(a, staircase_below_rad_s)) return {};
  return {a.omega_el_error_rad_s, a.omega_el_error_noise_rad_s};
}

}  // namespace rpem::core
