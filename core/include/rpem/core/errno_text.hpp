#pragma once
// The text of an errno value, safe from any thread: glibc's strerror is MT-Unsafe (its text may sit in a
// buffer another thread's call overwrites), strerror_r writes into the caller's. The same text as strerror,
// "Unknown error N" included. Start-up and error paths only: it builds a std::string.

#include <cstring>
#include <string>

namespace rpem::core {

[[nodiscard]] inline std::string errno_text(int error) {
  char buffer[256];
  // GNU strerror_r (g++ defines _GNU_SOURCE for C++): returns the text, in buffer or in a constant string.
  return ::strerror_r(error, buffer, sizeof buffer);
}

}  // namespace rpem::core
