#pragma once
// Windows held back until their speed can be counted (docs/rpemd.md, "source: vesc", "A Hall drive at a crawl").
// A Hall drive below its interpolation speed holds each state's angle, so the PLL speed it reports at a read is
// not its window's mean; the tachometer counts the steps exactly, but a 5 ms window holds none or one of them
// (one step in 5 ms is 209 rad/s). Each window's speed is therefore counted over a run of reads centred on it,
// grown while its two sides agree (core::grown_count_speed_rad_s, docs/derivations.md §13), up to
// core::kCountRunSideMaxS after it: the window waits that long. The source thread owns it; fixed capacity, no
// allocation after construction, nothing that throws.
//
//   add_read(r)      every decoded reply's read of the tachometer, in time order
//   add_window(w)    a window that ends at the newest read (not while full(): release the oldest first)
//   release(now, w)  the oldest window once the run after it is complete (now ≥ its end + the horizon) or the
//                    ring is full, with omega_counted_el_rad_s set; false when none is due
//
// Capacity: twice the horizon at the highest poll rate (2 kHz: 500 windows held; 2 048 reads are 1 s of them,
// the held windows' and the horizon's before them). Past it the oldest window leaves early (its run shorter
// after it) and the oldest read is dropped; a window whose reads are gone carries no count (its reported speed
// stands). No window is lost.

#include <array>
#include <cstddef>
#include <cstdint>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/reported_speed.hpp"

namespace rpem::daemon {

class CountDelay {
 public:
  static constexpr std::size_t kReads = 2048;
  static constexpr std::size_t kWindows = 1024;

  /// `step_rad`: the count's quantum (the tachometer's 60°); `side_max_s`: how long a window waits.
  CountDelay(double step_rad, double side_max_s) noexcept;

  void add_read(const core::CountRead& read) noexcept;
  void add_window(const core::AveragedSample& window) noexcept;
  [[nodiscard]] bool release(std::int64_t now_ns, core::AveragedSample& window) noexcept;

  [[nodiscard]] std::size_t held() const noexcept { return windows_held_; }
  [[nodiscard]] bool full() const noexcept { return windows_held_ == kWindows; }

 private:
  /// The reads held, as grown_count_speed_rad_s takes them: index 0 is the oldest.
  struct ReadView {
    const CountDelay* self;
    [[nodiscard]] std::size_t size() const noexcept { return self->reads_held_; }
    [[nodiscard]] const core::CountRead& operator[](std::size_t j) const noexcept {
      return self->reads_[(self->first_read_ + j) % kReads];
    }
  };
  struct Held {
    core::AveragedSample window;
    std::uint64_t end_read = 0;  ///< the sequence number of the read that ends it
  };

  double step_rad_;
  std::int64_t side_max_ns_;
  std::array<core::CountRead, kReads> reads_{};
  std::uint64_t first_read_ = 0;  ///< the sequence number of the oldest read held
  std::size_t reads_held_ = 0;
  std::array<Held, kWindows> windows_{};
  std::size_t first_window_ = 0;
  std::size_t windows_held_ = 0;
};

}  // namespace rpem::daemon
