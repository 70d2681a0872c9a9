#include "rpem/daemon/speed_error_delay.hpp"

#include <cmath>

#include "rpem/core/assert.hpp"
#include "rpem/core/clock.hpp"

namespace rpem::daemon {

SpeedErrorDelay::SpeedErrorDelay(const core::PllGains& pll) noexcept : pll_(pll), held_change_rad_s2_(std::nan("")) {
  changes_.fill(std::nan(""));
}

bool SpeedErrorDelay::on_read(double accel_change_rad_s2, core::AveragedSample& released) noexcept {
  changes_[next_change_] = accel_change_rad_s2;
  next_change_ = (next_change_ + 1) % changes_.size();
  if (!holding_) return false;
  holding_ = false;
  released = held_;
  if (!pll_.given()) return true;  // the speed is the window's own mean: no rebuild, no error
  const double h_s = core::to_seconds(released.t_ns - released.t_start_ns);
  // The larger change at the window's two ends (fmax: a NaN side left out); none at all: no error stated.
  const double change = std::fmax(std::fabs(held_change_rad_s2_), std::fabs(accel_change_rad_s2));
  if (std::isfinite(change)) released.omega_el_error_rad_s = core::window_mean_speed_error_rad_s(pll_, change, h_s);
  std::array<double, core::kAccelChangeRunReads> run = changes_;
  released.omega_el_error_noise_rad_s = core::window_mean_speed_error_rad_s(pll_, core::accel_change_sigma_rad_s2(run), h_s);
  return true;
}

void SpeedErrorDelay::hold(const core::AveragedSample& window) noexcept {
  RPEM_ASSERT(!holding_, "the reply that closed this window released the one before it (on_read first)");
  held_ = window;
  held_change_rad_s2_ = changes_[(next_change_ + changes_.size() - 1) % changes_.size()];  // the newest reply's
  holding_ = true;
}

}  // namespace rpem::daemon
