#pragma once
// What `rpem diagnose` shows while it runs and how Ctrl-C stops it (docs/diagnose.md, "Long recordings"):
// on a terminal, a progress bar on stderr — the stage, how far, the time left — once a run has taken
// longer than a few seconds, nothing when stderr is not a terminal; SIGINT and SIGTERM ask the diagnosis
// to stop between blocks (a second one ends the process at once).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "rpem/analysis/diagnose/monitor.hpp"

namespace rpem::tools {

class TerminalMonitor final : public analysis::Monitor {
 public:
  /// Installs the SIGINT and SIGTERM handlers (until destroyed); draws only if stderr is a terminal.
  TerminalMonitor();
  ~TerminalMonitor() override;
  TerminalMonitor(const TerminalMonitor&) = delete;
  TerminalMonitor& operator=(const TerminalMonitor&) = delete;

  void stage(std::string_view name, std::uint64_t work) override;
  void add_work(std::uint64_t units) override;
  void advance(std::uint64_t units) noexcept override;
  [[nodiscard]] bool stop_requested() const noexcept override;
  /// Reading the log: `done` of `total` bytes.
  void reading(std::uint64_t done, std::uint64_t total) noexcept;
  /// Clears the bar (before the summary is printed).
  void finish() noexcept;

 private:
  void draw(bool force) noexcept;

  using Clock = std::chrono::steady_clock;
  const bool tty_;
  const Clock::time_point start_ = Clock::now();
  std::mutex mutex_;  ///< the stage's name and the terminal line
  std::string stage_;
  Clock::time_point stage_start_ = start_;
  std::atomic<std::uint64_t> done_{0}, work_{0};
  std::atomic<std::int64_t> last_draw_ns_{0};
  bool drawn_ = false;
};

}  // namespace rpem::tools
