#pragma once
// What the example programs read from their command line beyond file names.

#include <cstdio>
#include <cstdlib>
#include <optional>

namespace rpem::supervisor {

/// SECONDS, how long to run: a whole number from 1 to 1e9; nullopt for anything else ("abc", "2.5", "-3", "1e3":
/// atoi read these as 0 s or 2 s).
[[nodiscard]] inline std::optional<long> parse_seconds(const char* text) noexcept {
  char* rest = nullptr;
  const long seconds = std::strtol(text, &rest, 10);
  if (rest == text || *rest != '\0' || seconds < 1 || seconds > 1'000'000'000) return std::nullopt;
  return seconds;
}

/// Says on stderr why `program` refused SECONDS `text` (parse_seconds gave nullopt).
inline void say_seconds_refused(const char* program, const char* text) {
  std::fprintf(stderr, "%s: SECONDS '%s' is not a whole number of seconds from 1 to 1e9\n", program, text);
}

}  // namespace rpem::supervisor
