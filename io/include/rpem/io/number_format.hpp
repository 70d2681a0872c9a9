#pragma once
// Shortest round-trip formatting of doubles for CSV output (std::to_chars): what is written reads
// back bit-exactly.

#include <charconv>
#include <string>

namespace rpem::io {

inline void append_number(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

}  // namespace rpem::io
