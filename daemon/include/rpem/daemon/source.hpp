#pragma once
// What every sample source is to rpemd. A source runs on its own thread (the Daemon starts it) and is
// the one producer of two queues: samples for the estimator loop, and reports of its counters for the
// publisher. Which sources exist, and how the configuration names them: source_catalogue.hpp.

#include <atomic>
#include <cstdint>
#include <string>
#include <utility>

#include "rpem/daemon/diagnostics_rows.hpp"
#include "rpem/daemon/source_sample.hpp"
#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {

/// A source's counters (and, for the simulated drive, its true parameters, for the status line).
struct SourceReport {
  DiagnosticsRows rows;
  bool has_truth = false;
  double truth_psi_m_Wb = 0.0;
  double truth_r_s_Ohm = 0.0;
  double truth_t_magnet_C = 0.0, truth_t_winding_C = 0.0;  ///< the temperatures behind them
};

/// The source thread's two outputs.
class SourceOutput {
 public:
  static constexpr std::int64_t kReportIntervalNs = 100'000'000;

  SourceOutput(SpscQueue<SourceSample>::Producer samples, SpscQueue<SourceReport>::Producer reports) noexcept
      : samples_(std::move(samples)), reports_(std::move(reports)) {}

  /// Queues a sample for the loop; a full queue drops it (diagnostics_t.input_queue_drops).
  void push(const SourceSample& s) noexcept {
    if (!samples_.push(s)) ++queue_drops_;
  }
  /// True when the next report is due (every kReportIntervalNs of `now_ns`, monotonic).
  [[nodiscard]] bool report_due(std::int64_t now_ns) const noexcept { return now_ns >= next_report_ns_; }
  /// Sends the source's report, with the drop count added. A full queue skips this one: the rows are
  /// totals, the next report carries them.
  void report(SourceReport r, std::int64_t now_ns) noexcept {
    r.rows.set(&rpem::diagnostics_t::input_queue_drops, queue_drops_);
    (void)reports_.push(r);
    next_report_ns_ = now_ns + kReportIntervalNs;
  }

 private:
  SpscQueue<SourceSample>::Producer samples_;
  SpscQueue<SourceReport>::Producer reports_;
  std::int64_t queue_drops_ = 0;
  std::int64_t next_report_ns_ = 0;
};

class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// The source thread's body: produces samples into `out` until `stop` is set (or, for a finite
  /// source, until it ends). Real-time policy and the thread's name are set by the caller.
  virtual void run(const std::atomic<bool>& stop, SourceOutput& out) = 0;
  /// What the source reads from, for the log and diagnostics_t.source_name (an interface, a scenario).
  [[nodiscard]] virtual std::string name() const = 0;
};

}  // namespace rpem::daemon
