#pragma once
// The loop thread — rpemd's fixed-rate, real-time estimator loop, the owner of the estimator. Each period
// (LoopTimer) it applies the commands the control thread queued, steps the estimator over every sample
// that arrived (in order), tracks validity and age (ValidityTracker), and queues reports for the
// publisher. The estimator is the one for the kind of sample the configured source produces
// (LoopEstimator): phase samples step DriveEstimator, averaged rotor-frame samples AveragedDriveEstimator
// at their host timestamps. With a thermal network configured, its Kalman filter (core::ThermalFusion) steps
// beside the estimator on every sample and RPEM_ESTIMATE carries the fused temperatures. It never allocates, locks, logs or does I/O once running: everything it touches was
// allocated before; a full output queue drops the report and counts it.

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "rpem/core/plausibility.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/core/thermal_fusion.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/loop_estimator.hpp"
#include "rpem/daemon/loop_timer.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/sensor_reading.hpp"
#include "rpem/daemon/spsc_queue.hpp"
#include "rpem/daemon/validity.hpp"

namespace rpem::daemon {

/// The loop's counters: it is their one writer (published through a table in loop_thread.cpp).
struct LoopCounters {
  std::int64_t samples = 0;
  std::int64_t resyncs = 0;
  std::int64_t rejected_non_finite = 0;
  std::int64_t rejected_implausible = 0;  ///< samples with a value beyond what the machine produces (plausible_)
  std::int64_t wrong_kind = 0;            ///< samples of the kind the source does not produce (never expected)
  std::int64_t predictor_resets = 0;
  std::int64_t projections = 0;
  std::int64_t output_queue_drops = 0;
  std::int64_t commands_applied = 0;         ///< supervisory commands (seq > 0)
  std::int64_t command_sequence_errors = 0;  ///< an applied command not after the previous one (never expected)
  std::int64_t config_reloads = 0;           ///< reloads applied
  std::int64_t outliers = 0;                 ///< samples skipped by the outlier bound
  core::RegimeCounts regimes;                ///< samples per regime (core/regime.hpp)
};

/// A value from the state file and how long ago it last adapted.
struct SeedValue {
  double value = 0.0;
  double age_s = 0.0;
};

class LoopThread {
 public:
  struct Queues {
    SpscQueue<SourceSample>::Consumer samples;  ///< from the source thread
    SpscQueue<Command>::Consumer commands;      ///< from the control thread
    SpscQueue<Report>::Producer reports;        ///< to the publisher
  };

  LoopThread(const DaemonConfig& config, Queues queues);

  /// Seeds the estimates (from the state file) before the loop runs; `now_ns` on the loop's clock.
  void seed(const std::optional<SeedValue>& psi_m_Wb, const std::optional<SeedValue>& r_s_Ohm, std::int64_t now_ns);
  /// The thermal fusion's first step starts from a state saved `gap_s` ago (core::ThermalFusion::resume); false
  /// where no network runs or the state is not of its network. Before the loop runs.
  bool resume_thermal(const core::ThermalSnapshot& saved, double gap_s) noexcept;

  /// The thread body: runs until `stop` is set, then reports a last estimate. Sets up the thread's
  /// real-time policy first (problems: setup_problems(), then started()).
  void run(const std::atomic<bool>& stop);

  /// One period's work without the sleep, for tests: commands, samples, reports. `now_ns` is the
  /// monotonic time of the period. Real-time safe.
  void process(std::int64_t now_ns) noexcept;

  [[nodiscard]] bool started() const noexcept { return started_.load(std::memory_order_acquire); }
  /// Problems met while applying the real-time policy (empty when all was granted); after started().
  [[nodiscard]] const std::string& setup_problems() const noexcept { return setup_problems_; }
  [[nodiscard]] const LoopTimer& timer() const noexcept { return timer_; }

 private:
  void apply(const Command& c) noexcept;
  /// The next sample starts a new stream; a window the estimator takes back here is taken back by all who counted it.
  void resynchronize() noexcept;
  void step(const SourceSample& s, std::int64_t now_ns) noexcept;
  void report_measurement() noexcept;
  void report_estimate(std::int64_t now_ns) noexcept;
  void report_thermal(EstimateReport& r) const noexcept;
  void report_stats() noexcept;
  void push(const Report& r) noexcept;

  LiveConfig live_;
  const LoopConfig loop_config_;
  Queues queues_;
  /// What the configured machine's samples may hold (core::machine_plausible): a live source's value beyond it —
  /// a corrupted read, a wrong scale in a signal map — is not estimated on (docs/rpemd.md, "Values no drive produces").
  core::PlausibleMagnitudes plausible_;
  LoopEstimator estimator_;
  ValidityTracker validity_;
  core::ThermalFusion thermal_;  ///< stepped only while live_.thermal_active
  LoopTimer timer_;
  std::string setup_problems_;
  std::atomic<bool> started_{false};

  std::int64_t estimate_interval_ns_, measurement_interval_ns_, stats_interval_ns_;
  std::int64_t next_estimate_ns_ = 0, next_measurement_ns_ = 0, next_stats_ns_ = 0;

  DaemonState state_ = DaemonState::kStarting;
  std::int64_t last_sample_mono_ns_ = 0;
  core::Estimate last_;
  SampleSummary last_sample_;
  SensorReading winding_sensor_, drive_sensor_, coolant_sensor_;  ///< the drive's own, for RPEM_MEASUREMENT
  LoopCounters counters_;
  double eps2_d_ = 0.0, eps2_q_ = 0.0;
  std::int64_t eps_n_ = 0;
  std::int64_t last_applied_seq_ = 0;

  // The last good values (valid, converged, adapting), for the state file.
  bool has_good_[2] = {false, false};
  double good_[2] = {0.0, 0.0};
  std::int64_t good_ns_[2] = {0, 0};
};

}  // namespace rpem::daemon
