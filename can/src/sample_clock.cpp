#include "rpem/can/sample_clock.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace rpem::can {

SampleClock::SampleClock(int length, bool is_float, double scale_s, double offset_s) noexcept
    : is_float_(is_float),
      // 2^length counts per wrap; a 63- or 64-bit counter does not wrap in any drive's lifetime.
      span_(is_float || length >= 63 ? 0 : std::int64_t{1} << length),
      scale_s_(scale_s),
      offset_s_(offset_s) {
  assert(scale_s_ > 0.0);  // can::check_layout refuses any other
}

void SampleClock::on_value(std::uint64_t raw_bits, double value_s) noexcept {
  if (is_float_) {
    value_s_ = value_s;
  } else {
    raw_ = span_ > 0 ? raw_bits & static_cast<std::uint64_t>(span_ - 1) : raw_bits;
  }
}

bool SampleClock::forward_of(std::uint64_t earlier_raw) const noexcept {
  const std::uint64_t delta = raw_ - earlier_raw;
  if (span_ == 0) return static_cast<std::int64_t>(delta) > 0;
  const std::uint64_t wrapped = delta & static_cast<std::uint64_t>(span_ - 1);
  return wrapped > 0 && wrapped < static_cast<std::uint64_t>(span_ / 2);
}

SampleClock::Step SampleClock::close(std::int64_t rx_ns, std::int64_t& t_ns) noexcept {
  // A time or step beyond kMaxClockS is no drive's clock (and would overflow nanoseconds): stale.
  const double now_s = is_float_ ? value_s_ : static_cast<double>(raw_) * scale_s_ + offset_s_;
  if (!(std::abs(now_s) < kMaxClockS)) return Step::kStale;
  if (!started_) {
    t_ns = std::llround(now_s * 1e9);
    remember(rx_ns, t_ns);
    return Step::kFirst;
  }
  const std::int64_t rx_step_ns = rx_ns - previous_rx_ns_;
  double step_s = 0.0;
  if (is_float_) {
    step_s = value_s_ - previous_value_s_;
  } else {
    // The drive's step in counts: the wrapped difference plus the whole wraps that bring it nearest the
    // receive step (none for a counter that does not wrap); behind the previous sample: negative.
    const auto delta = static_cast<std::int64_t>(raw_ - previous_raw_);
    double counts = static_cast<double>(delta);
    if (span_ > 0) {
      const auto wrapped = static_cast<double>(delta & (span_ - 1));
      const double rx_counts = static_cast<double>(rx_step_ns) * 1e-9 / scale_s_;
      const double wraps = std::round((rx_counts - wrapped) / static_cast<double>(span_));
      counts = wraps < 0.0 ? -1.0 : wrapped + wraps * static_cast<double>(span_);
    }
    step_s = counts * scale_s_;
  }
  if (!(step_s > 0.0 && step_s < kMaxClockS)) {
    // A restarted clock runs: stale samples that advance among themselves. A stopped one never restarts.
    const bool advances = is_float_ ? value_s_ > stale_value_s_ : forward_of(stale_raw_);
    stale_run_ = stale_run_ > 0 && advances ? stale_run_ + 1 : 1;
    stale_raw_ = raw_;
    stale_value_s_ = value_s_;
    if (stale_run_ < kRestartAfterStale) return Step::kStale;
    // The drive's clock restarted: go on from the previous time by the receive step, as a gap.
    t_ns = previous_t_ns_ + std::max<std::int64_t>(rx_step_ns, 1);
    remember(rx_ns, t_ns);
    return Step::kFirst;
  }
  t_ns = previous_t_ns_ + std::max<std::int64_t>(std::llround(step_s * 1e9), 1);
  remember(rx_ns, t_ns);
  return Step::kNext;
}

void SampleClock::remember(std::int64_t rx_ns, std::int64_t t_ns) noexcept {
  started_ = true;
  stale_run_ = 0;
  previous_raw_ = raw_;
  previous_value_s_ = is_float_ ? value_s_ : 0.0;
  previous_t_ns_ = t_ns;
  previous_rx_ns_ = rx_ns;
}

}  // namespace rpem::can
