#include "diagnose_monitor.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>

namespace rpem::tools {
namespace {

/// Set by the signal handlers: the diagnosis stops between blocks.
std::atomic<bool> g_diagnose_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

void on_diagnose_stop_signal(int) { g_diagnose_stop.store(true); }

/// A bar is drawn once the run has taken this long (a short run stays quiet) …
constexpr auto kQuietFor = std::chrono::seconds(2);
/// … and redrawn at most this often.
constexpr std::int64_t kRedrawEveryNs = 200'000'000;
constexpr int kBarWidth = 24;

std::string duration_text(double s) {
  char text[32];
  if (s < 60.0) {
    std::snprintf(text, sizeof text, "%.0f s", s);
  } else {
    std::snprintf(text, sizeof text, "%d min %02d s", static_cast<int>(s / 60.0), static_cast<int>(s) % 60);
  }
  return text;
}

}  // namespace

TerminalMonitor::TerminalMonitor() : tty_(isatty(STDERR_FILENO) != 0) {
  g_diagnose_stop.store(false);
  struct sigaction action {};
  action.sa_handler = on_diagnose_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // a second Ctrl-C ends the process at once
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

TerminalMonitor::~TerminalMonitor() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  finish();
}

void TerminalMonitor::stage(std::string_view name, std::uint64_t work) {
  {
    const std::lock_guard lock(mutex_);
    stage_ = name;
    stage_start_ = Clock::now();
    done_.store(0);
    work_.store(work);
  }
  draw(true);
}

void TerminalMonitor::add_work(std::uint64_t units) { work_ += units; }

void TerminalMonitor::advance(std::uint64_t units) noexcept {
  done_ += units;
  draw(false);
}

bool TerminalMonitor::stop_requested() const noexcept { return g_diagnose_stop.load(); }

void TerminalMonitor::reading(std::uint64_t done, std::uint64_t total) noexcept {
  {
    const std::lock_guard lock(mutex_);
    if (stage_.empty()) {
      stage_ = "reading the log";
      stage_start_ = Clock::now();
    }
    work_.store(total);
    done_.store(done);
  }
  draw(false);
}

void TerminalMonitor::draw(bool force) noexcept {
  if (!tty_) return;
  const Clock::time_point now = Clock::now();
  if (now - start_ < kQuietFor) return;
  const std::int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - start_).count();
  std::int64_t last = last_draw_ns_.load();
  if (!force && now_ns - last < kRedrawEveryNs) return;
  if (!last_draw_ns_.compare_exchange_strong(last, now_ns) && !force) return;  // another thread draws
  const std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  const std::uint64_t work = work_.load(), done = std::min(done_.load(), work);
  const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
  std::string line = "\r\033[K" + stage_;
  if (work > 0) {
    const double fraction = static_cast<double>(done) / static_cast<double>(work);
    const int filled = static_cast<int>(fraction * kBarWidth);
    line += " [" + std::string(static_cast<std::size_t>(filled), '#') +
            std::string(static_cast<std::size_t>(kBarWidth - filled), '.') + "] ";
    char percent[16];
    std::snprintf(percent, sizeof percent, "%3.0f %%", 100.0 * fraction);
    line += percent;
    if (fraction > 0.02 && elapsed > 1.0) line += ", " + duration_text(elapsed * (1.0 - fraction) / fraction) + " left";
  } else {
    line += " (" + duration_text(elapsed) + ")";
  }
  line += ", " + duration_text(std::chrono::duration<double>(now - start_).count()) + " in all";
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  drawn_ = true;
}

void TerminalMonitor::finish() noexcept {
  const std::lock_guard lock(mutex_);
  if (!drawn_) return;
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace rpem::tools
