#include "rpem/daemon/count_delay.hpp"

#include <cmath>

#include "rpem/core/assert.hpp"

namespace rpem::daemon {

CountDelay::CountDelay(double step_rad, double side_max_s) noexcept
    : step_rad_(step_rad), side_max_ns_(std::llround(side_max_s * 1e9)) {
  RPEM_ASSERT(step_rad > 0.0 && side_max_s >= 0.0, "a count has a step and a window waits no negative time");
}

void CountDelay::add_read(const core::CountRead& read) noexcept {
  if (reads_held_ == kReads) {
    ++first_read_;
    --reads_held_;
  }
  reads_[(first_read_ + reads_held_) % kReads] = read;
  ++reads_held_;
}

void CountDelay::add_window(const core::AveragedSample& window) noexcept {
  RPEM_ASSERT(reads_held_ > 0, "a window ends at a read, added before it");
  RPEM_ASSERT(!full(), "the caller releases a full ring's oldest window first");
  windows_[(first_window_ + windows_held_) % kWindows] = {window, first_read_ + reads_held_ - 1};
  ++windows_held_;
}

bool CountDelay::release(std::int64_t now_ns, core::AveragedSample& window) noexcept {
  if (windows_held_ == 0) return false;
  const Held& h = windows_[first_window_];
  if (now_ns - h.window.t_ns < side_max_ns_ && !full()) return false;
  window = h.window;
  window.omega_counted_el_rad_s = std::nan("");
  if (h.end_read > first_read_) {  // the read before it, where it starts, is still held
    const auto e = static_cast<std::size_t>(h.end_read - first_read_);
    window.omega_counted_el_rad_s = core::grown_count_speed_rad_s(ReadView{this}, e - 1, e, step_rad_, side_max_ns_);
  }
  first_window_ = (first_window_ + 1) % kWindows;
  --windows_held_;
  return true;
}

}  // namespace rpem::daemon
