#include "rpem/schema/text.hpp"

#include <charconv>
#include <system_error>

namespace rpem::schema::detail {

// std::to_chars: the C locale's printf conversions without a locale or a buffer on the heap.
void append_number(std::string& out, double v) {
  char buf[32];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6);
  out.append(buf, r.ec == std::errc{} ? r.ptr : buf);
}

void append_number(std::string& out, std::int64_t v) {
  char buf[24];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ec == std::errc{} ? r.ptr : buf);
}

void append_quoted(std::string& out, std::string_view text) {
  out += '"';
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  out += '"';
}

}  // namespace rpem::schema::detail
