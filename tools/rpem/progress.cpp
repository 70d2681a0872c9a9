#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace rpem::tools {

Progress::Progress(std::string label)
    : label_(std::move(label)),
      tty_(isatty(STDERR_FILENO) != 0),
      last_print_(std::chrono::steady_clock::now()),
      start_(last_print_) {}

void Progress::update(std::uint64_t done, std::uint64_t total) {
  if (total == 0) return;
  const double fraction = static_cast<double>(done) / static_cast<double>(total);
  const auto now = std::chrono::steady_clock::now();
  if (tty_) {
    if (now - last_print_ < std::chrono::milliseconds(200)) return;
    last_print_ = now;
    std::fprintf(stderr, "\r%s: %5.1f %%", label_.c_str(), 100.0 * fraction);
    std::fflush(stderr);
    return;
  }
  const int decile = static_cast<int>(fraction * 10.0);
  if (decile > last_decile_ && decile > 0 && decile < 10) {
    last_decile_ = decile;
    std::fprintf(stderr, "%s: %d %%\n", label_.c_str(), decile * 10);
  }
}

void Progress::finish(const std::string& summary) {
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "%s%s: %s (%.2f s)\n", tty_ ? "\r" : "", label_.c_str(), summary.c_str(), s);
}

}  // namespace rpem::tools
