#pragma once
// What a long diagnosis tells whoever runs it as it goes, and how that caller stops it (docs/diagnose.md,
// "Long recordings"): each stage's name and, where it is known beforehand, its amount of work; the work
// done (samples replayed, per model, or run through the estimator); between blocks, whether to stop — then
// the diagnosis throws Interrupted and leaves nothing behind. Stages begin on the diagnosing thread; work is
// reported from any thread of the pool.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>

namespace rpem::analysis {

class Monitor {
 public:
  virtual ~Monitor() = default;
  /// A stage begins: its name ("calibrating the baseline", "round 2: screening 20 candidates") and its work
  /// in the units advance() counts (0: not known beforehand).
  virtual void stage(std::string_view name, std::uint64_t work) { (void)name, (void)work; }
  /// The current stage turns out to hold `units` more work than announced (known only once it has begun).
  virtual void add_work(std::uint64_t units) { (void)units; }
  /// `units` more of the current stage's work are done. Thread-safe.
  virtual void advance(std::uint64_t units) noexcept { (void)units; }
  /// Whether the caller asked the diagnosis to stop. Thread-safe.
  [[nodiscard]] virtual bool stop_requested() const noexcept { return false; }
};

/// Thrown out of a diagnosis that its caller stopped (Monitor::stop_requested).
struct Interrupted : std::exception {
  [[nodiscard]] const char* what() const noexcept override { return "interrupted"; }
};

/// Samples a sequential run over the log (an estimator's) goes between two looks at the monitor.
inline constexpr std::size_t kMonitorSamples = std::size_t{1} << 16;

/// Tells `monitor` (if any) of `units` more work done, and throws Interrupted if it asks to stop.
inline void report_work(Monitor* monitor, std::uint64_t units) {
  if (!monitor) return;
  monitor->advance(units);
  if (monitor->stop_requested()) throw Interrupted();
}

}  // namespace rpem::analysis
