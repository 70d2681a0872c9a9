#pragma once
// The fixed-rate estimator loop — rpemd's real-time thread. Each period (clock_nanosleep, TIMER_ABSTIME,
// CLOCK_MONOTONIC) it records its wake-up latency, applies pending commands, steps the estimator over
// every sample that arrived (in order), derives temperatures, validity and convergence, and pushes
// reports for the publisher. It never allocates, locks, logs or does I/O once running: everything it
// touches was allocated before; a full output queue drops the report and counts it.

#include <array>
#include <atomic>
#include <cstdint>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/latency_histogram.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {

class EstimatorLoop {
 public:
  EstimatorLoop(const DaemonConfig& config, SpscQueue<core::DriveSample>& input, SpscQueue<Command>& commands,
                SpscQueue<Report>& output);

  /// Seeds the estimates (from the state file) before the loop runs.
  void seed(const std::optional<double>& psi_m_Wb, const std::optional<double>& r_s_Ohm);

  /// The thread body: runs until `stop` is set. Sets up the thread's policy first.
  void run(std::atomic<bool>& stop);

  /// Incremented every period: the watchdog's sign of life.
  [[nodiscard]] std::uint64_t heartbeat() const noexcept { return heartbeat_.load(std::memory_order_acquire); }
  /// Problems met while applying the real-time policy (empty when all was granted).
  [[nodiscard]] const std::string& setup_problems() const noexcept { return setup_problems_; }
  [[nodiscard]] bool started() const noexcept { return started_.load(std::memory_order_acquire); }
  /// Whole-run wake-up latency and overruns (read after the loop has stopped).
  [[nodiscard]] const LatencyHistogram& run_latency() const noexcept { return run_latency_; }
  [[nodiscard]] std::int64_t overruns() const noexcept { return overruns_; }
  [[nodiscard]] std::int64_t periods() const noexcept { return periods_; }
  /// The timer anticipation in use [ns]; with `wake_ahead_s: auto`, −1 until calibrated.
  [[nodiscard]] std::int64_t wake_ahead_ns() const noexcept { return wake_ahead_published_ns_.load(std::memory_order_acquire); }

  /// One period's work without the sleep, for tests: commands, samples, reports. `now_ns` is the
  /// monotonic time of the period. Real-time safe.
  void process(std::int64_t now_ns) noexcept;

 private:
  void apply(const Command& c) noexcept;
  void step(const core::DriveSample& s) noexcept;
  void report_estimate(std::int64_t now_ns) noexcept;
  void report_stats(std::int64_t now_ns) noexcept;
  void push(const Report& r) noexcept;
  [[nodiscard]] bool converged(const std::array<double, 64>& ring, int count) const noexcept;

  DaemonConfig config_;
  SpscQueue<core::DriveSample>& input_;
  SpscQueue<Command>& commands_;
  SpscQueue<Report>& output_;
  core::DriveEstimator estimator_;
  std::string setup_problems_;
  std::atomic<std::uint64_t> heartbeat_{0};
  std::atomic<bool> started_{false};

  // Timing
  std::int64_t period_ns_;
  std::int64_t wake_ahead_ns_;
  std::int64_t wake_ahead_calibration_periods_;  ///< > 0: `auto`, calibrate after this many periods
  std::atomic<std::int64_t> wake_ahead_published_ns_;
  std::int64_t estimate_interval_ns_, measurement_interval_ns_, stats_interval_ns_;
  std::int64_t next_estimate_ns_ = 0, next_measurement_ns_ = 0, next_stats_ns_ = 0;
  LatencyHistogram latency_;      ///< this reporting interval
  LatencyHistogram run_latency_;  ///< the whole run
  double work_max_us_ = 0.0;
  std::int64_t overruns_ = 0, periods_ = 0;

  // Stream state
  DaemonState state_ = DaemonState::kStarting;
  std::int64_t last_sample_mono_ns_ = 0;
  core::Estimate last_;
  core::DriveSample last_sample_;
  std::int64_t samples_ = 0, resyncs_ = 0, rejected_ = 0, predictor_resets_ = 0, projections_ = 0;
  double eps2_d_ = 0.0, eps2_q_ = 0.0;
  std::int64_t eps_n_ = 0;

  // Validity and convergence
  double r_s_adapted_s_ = 0.0, psi_m_adapted_s_ = 0.0;
  bool r_s_valid_ = false;
  std::array<double, 64> psi_ring_{}, rs_ring_{};
  int ring_count_ = 0, ring_head_ = 0, ring_size_ = 1;
  bool has_good_psi_ = false, has_good_rs_ = false;
  double good_psi_ = 0.0, good_rs_ = 0.0;

  // Commands
  std::int64_t last_seq_ = 0;
  CommandResult last_result_ = CommandResult::kNone;
  std::int64_t commands_applied_ = 0, config_reloads_ = 0;
  std::int64_t output_drops_ = 0;
};

}  // namespace rpem::daemon
