#include "rpem/supervisor/report.hpp"

#include <cstdio>

namespace rpem::supervisor {
namespace {

std::string part(const char* name, const std::optional<double>& upper_C, double current_A) {
  char t[32] = "unknown";
  if (upper_C) std::snprintf(t, sizeof t, "%.1f C", *upper_C);
  char line[96];
  std::snprintf(line, sizeof line, " | %s T+ %s -> %.2f A", name, t, current_A);
  return line;
}

std::string line(const std::string& what, std::optional<std::int64_t> utime_us, const CurrentLimit& l) {
  char head[128];
  const std::string when = utime_us ? std::to_string(*utime_us) : std::string("-");
  std::snprintf(head, sizeof head, "%s %s: I_max %.2f A", what.c_str(), when.c_str(), l.current_A);
  return head + part("magnet", l.magnet_upper_C, l.magnet_A) + part("winding", l.winding_upper_C, l.winding_A);
}

}  // namespace

std::string verdict_line(const Received& received, const CurrentLimit& limit) {
  const Admission a = received.verdict;
  return line(a == Admission::kAccepted ? std::string("accepted") : std::string("ignored (") + to_string(a) + ")",
              received.utime_us, limit);
}

std::string limit_line(std::int64_t now_unix_us, const CurrentLimit& limit) {
  return line(limit.fresh ? "limit" : "limit (no fresh estimate)", now_unix_us, limit);
}

}  // namespace rpem::supervisor
