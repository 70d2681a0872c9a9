#pragma once
// Time as integer nanoseconds (DriveSample::t_ns, kernel receive stamps, rpemd's schedule): the
// conversions from and to POSIX time structures, reading a clock, and sleeping to an absolute time.
// Written once here; can/, daemon/, tools/, bench/ and tests include it.

#include <sys/time.h>

#include <cerrno>
#include <cstdint>
#include <ctime>

namespace rpem::core {

inline constexpr std::int64_t kNsPerS = 1'000'000'000;

[[nodiscard]] constexpr std::int64_t to_ns(const timespec& t) noexcept {
  return static_cast<std::int64_t>(t.tv_sec) * kNsPerS + t.tv_nsec;
}
[[nodiscard]] constexpr std::int64_t to_ns(const timeval& t) noexcept {
  return static_cast<std::int64_t>(t.tv_sec) * kNsPerS + static_cast<std::int64_t>(t.tv_usec) * 1000;
}
/// A time or an interval in integer nanoseconds, in seconds: 1e-9·t (the one spelling of it, so every
/// layer rounds alike).
[[nodiscard]] constexpr double to_seconds(std::int64_t t_ns) noexcept { return 1e-9 * static_cast<double>(t_ns); }
/// For t_ns ≥ 0.
[[nodiscard]] constexpr timespec to_timespec(std::int64_t t_ns) noexcept {
  return timespec{static_cast<time_t>(t_ns / kNsPerS), static_cast<long>(t_ns % kNsPerS)};
}

/// The time on `clock` [ns]. CLOCK_MONOTONIC and CLOCK_REALTIME are read through the vDSO: no system
/// call, real-time safe.
[[nodiscard]] inline std::int64_t now_ns(clockid_t clock) noexcept {
  timespec ts{};
  clock_gettime(clock, &ts);
  return to_ns(ts);
}

/// The time since the Unix epoch [µs]: LCM's `utime`, rpemd's publication times. Real-time safe (as now_ns).
[[nodiscard]] inline std::int64_t unix_us() noexcept { return now_ns(CLOCK_REALTIME) / 1000; }

/// Sleeps until `t_ns` on `clock` (clock_nanosleep, TIMER_ABSTIME), resuming after a signal handler
/// interrupted it: an absolute deadline does not drift however often that happens.
inline void sleep_until_ns(clockid_t clock, std::int64_t t_ns) noexcept {
  const timespec ts = to_timespec(t_ns);
  while (clock_nanosleep(clock, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace rpem::core
