#pragma once
// Shortest round-trip formatting of doubles for CSV output (std::to_chars): what is written reads
// back bit-exactly; and a count with its noun for messages.

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>

namespace rpem::io {

inline void append_number(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

/// "1 poll", "0 polls", "16 polls": `noun` is singular and takes an s.
inline std::string counted(std::uint64_t n, std::string_view noun) {
  std::string s = std::to_string(n);
  (s += ' ') += noun;
  if (n != 1) s += 's';
  return s;
}

}  // namespace rpem::io
