#pragma once
// The estimator loop's clock: a fixed-rate schedule on CLOCK_MONOTONIC (clock_nanosleep, TIMER_ABSTIME)
// with optional timer anticipation (loop.wake_ahead_s: sleep until that long before each deadline,
// then spin to it; `auto` calibrates it from the first second), wake-up latency statistics, work time,
// overruns, and the heartbeat the watchdog reads. Owned by the loop thread; heartbeat() and
// wake_ahead_ns() are atomics another thread may read; the run totals are read after the loop ends.

#include <atomic>
#include <cstdint>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"
#include "rpem/daemon/latency_histogram.hpp"

namespace rpem::daemon {

class LoopTimer {
 public:
  explicit LoopTimer(const LoopConfig& config) noexcept;

  /// Starts the schedule: the first deadline is one period from now. Returns now.
  std::int64_t start() noexcept;
  /// Sleeps (and spins) to the next deadline; records how late it woke. Returns the time it woke.
  std::int64_t wait() noexcept;
  /// After the period's work: its duration, an overrun if the next deadline has passed (the schedule
  /// restarts from now), the anticipation's calibration, the heartbeat.
  void finish(std::int64_t woke) noexcept;
  /// The last interval's latency and work figures and the totals into `rows`; starts a new interval.
  void report(DiagnosticsRows& rows) noexcept;

  [[nodiscard]] std::int64_t period_ns() const noexcept { return period_ns_; }
  /// Incremented every period: the watchdog's sign of life.
  [[nodiscard]] std::uint64_t heartbeat() const noexcept { return heartbeat_.load(std::memory_order_acquire); }
  /// The anticipation in use [ns]; with `wake_ahead_s: auto`, −1 until calibrated.
  [[nodiscard]] std::int64_t wake_ahead_ns() const noexcept {
    return wake_ahead_published_ns_.load(std::memory_order_acquire);
  }
  /// Whole-run figures (read after the loop has stopped).
  [[nodiscard]] const LatencyHistogram& run_latency() const noexcept { return run_latency_; }
  [[nodiscard]] std::int64_t overruns() const noexcept { return overruns_; }
  [[nodiscard]] std::int64_t periods() const noexcept { return periods_; }

 private:
  std::int64_t period_ns_;
  std::int64_t wake_ahead_ns_;
  std::int64_t calibration_periods_;  ///< > 0: `auto`, calibrate after this many periods
  std::atomic<std::int64_t> wake_ahead_published_ns_;
  std::atomic<std::uint64_t> heartbeat_{0};
  std::int64_t next_ns_ = 0;
  LatencyHistogram latency_;      ///< this reporting interval
  LatencyHistogram run_latency_;  ///< the whole run
  double work_max_us_ = 0.0;
  std::int64_t overruns_ = 0, periods_ = 0;
};

}  // namespace rpem::daemon
