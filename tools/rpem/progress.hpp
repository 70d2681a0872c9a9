#pragma once
// Progress on stderr for long runs: a rewritten line on a terminal, a line per 10 % otherwise.

#include <chrono>
#include <cstdint>
#include <string>

namespace rpem::tools {

class Progress {
 public:
  explicit Progress(std::string label);
  /// Reports `done` of `total` units (bytes, samples…); cheap to call often.
  void update(std::uint64_t done, std::uint64_t total);
  void finish(const std::string& summary);

 private:
  std::string label_;
  bool tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point last_print_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace rpem::tools
