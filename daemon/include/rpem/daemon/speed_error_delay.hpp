#pragma once
// Windows held back one reply until their speed's error can be judged from the reads at both their ends (docs/rpemd.md,
// "source: vesc"; docs/derivations.md §13, "… where the acceleration changes"). A reply's ERPM is the PLL's speed at
// the read, and the window's mean speed is rebuilt from it and the previous reply's: exact for a ramp. Where the
// acceleration changes inside a window (a hard stop), the PLL's speed shows it by the next read, not yet at the
// window's own end read; so each window waits for the next reply and takes the larger of the two changes of
// acceleration (core::window_mean_speed_error_rad_s) — as the VESC Tool log's reader does with the whole log at hand.
// Its noise is the latest core::kAccelChangeRunReads changes' (core::accel_change_sigma_rad_s2). The source thread
// owns it; no allocation, nothing that throws.
//
//   on_read(change, window)   every decoded reply, with the change of acceleration it shows (VescPoller::
//                             last_accel_change_rad_s2; NaN: none), first: releases the window held (true), its
//                             error and noise set
//   hold(window)              then the window that reply closed, if it closed one (its own change: the reply's)
//
// A window's release waits one poll period (5 ms at 200 Hz); a reply that closes no window (a gap, a timeout)
// still releases the one held, judged by its own end read alone.

#include <array>
#include <cstddef>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/reported_speed.hpp"

namespace rpem::daemon {

class SpeedErrorDelay {
 public:
  explicit SpeedErrorDelay(const core::PllGains& pll) noexcept;

  [[nodiscard]] bool on_read(double accel_change_rad_s2, core::AveragedSample& released) noexcept;
  void hold(const core::AveragedSample& window) noexcept;

  [[nodiscard]] bool holding() const noexcept { return holding_; }

 private:
  core::PllGains pll_;
  core::AveragedSample held_;
  bool holding_ = false;
  double held_change_rad_s2_ = 0.0;  ///< the change at the held window's end read (NaN: none)
  /// The latest changes (a ring; NaN: none yet): their noise.
  std::array<double, core::kAccelChangeRunReads> changes_{};
  std::size_t next_change_ = 0;
};

}  // namespace rpem::daemon
