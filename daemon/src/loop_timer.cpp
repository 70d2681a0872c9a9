#include "rpem/daemon/loop_timer.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/clock.hpp"
#include "rpem/daemon/realtime.hpp"

namespace rpem::daemon {

LoopTimer::LoopTimer(const LoopConfig& c) noexcept
    : period_ns_(static_cast<std::int64_t>(c.period_s * 1e9)),
      wake_ahead_ns_(static_cast<std::int64_t>(c.wake_ahead_s * 1e9)),
      calibration_periods_(c.wake_ahead_auto ? std::max<std::int64_t>(1, std::llround(1.0 / c.period_s)) : 0),
      wake_ahead_published_ns_(c.wake_ahead_auto ? -1 : wake_ahead_ns_) {}

std::int64_t LoopTimer::start() noexcept {
  next_ns_ = core::now_ns(CLOCK_MONOTONIC);
  return next_ns_;
}

std::int64_t LoopTimer::wait() noexcept {
  next_ns_ += period_ns_;
  core::sleep_until_ns(CLOCK_MONOTONIC, next_ns_ - wake_ahead_ns_);
  std::int64_t woke = core::now_ns(CLOCK_MONOTONIC);
  while (woke < next_ns_) {  // timer anticipation (loop.wake_ahead_s): spin to the deadline
    spin_pause();
    woke = core::now_ns(CLOCK_MONOTONIC);
  }
  const double late_us = 1e-3 * static_cast<double>(woke - next_ns_);
  latency_.add(late_us);
  run_latency_.add(late_us);
  return woke;
}

void LoopTimer::finish(std::int64_t woke) noexcept {
  ++periods_;
  const std::int64_t done = core::now_ns(CLOCK_MONOTONIC);
  work_max_us_ = std::max(work_max_us_, 1e-3 * static_cast<double>(done - woke));
  if (done > next_ns_ + period_ns_) {
    // The next deadline has passed: count it and restart the schedule from now.
    ++overruns_;
    next_ns_ = done - done % period_ns_;
  }
  if (periods_ == calibration_periods_) {
    // `wake_ahead_s: auto`: anticipate by the median wake-up latency of the first second (a one-off
    // scan of the histogram's bins, a few µs).
    wake_ahead_ns_ = std::min<std::int64_t>(period_ns_ / 2, std::llround(1e3 * run_latency_.percentile(0.5)));
    wake_ahead_published_ns_.store(wake_ahead_ns_, std::memory_order_release);
  }
  heartbeat_.fetch_add(1, std::memory_order_release);
}

void LoopTimer::report(DiagnosticsRows& rows) noexcept {
  using Diag = rpem::diagnostics_t;
  rows.set(&Diag::loop_period_ns, period_ns_);
  rows.set(&Diag::overruns, overruns_);
  rows.set(&Diag::loop_periods, periods_);
  rows.set(&Diag::wakeup_latency_min_us, latency_.min());
  rows.set(&Diag::wakeup_latency_mean_us, latency_.mean());
  rows.set(&Diag::wakeup_latency_max_us, latency_.max());
  rows.set(&Diag::wakeup_latency_p99_us, latency_.percentile(0.99));
  rows.set(&Diag::loop_work_max_us, work_max_us_);
  latency_.reset();
  work_max_us_ = 0.0;
}

}  // namespace rpem::daemon
