#include "rpem/daemon/status_line.hpp"

#include <cstdint>
#include <cstdio>

#include "rpem/mirror/diagnostics_t.hpp"

namespace rpem::daemon {
namespace {

/// After a parameter's value: "*" adapting, " held N s" held since its last adaptation; "?" when not valid.
std::string mark(bool adapting, double age_s, bool valid) {
  char buf[32];
  if (adapting) {
    std::snprintf(buf, sizeof buf, "*%s", valid ? "" : "?");
  } else if (age_s >= 0.0) {
    std::snprintf(buf, sizeof buf, " held %.0f s%s", age_s, valid ? "" : "?");
  } else {
    std::snprintf(buf, sizeof buf, "%s", valid ? "" : "?");
  }
  return buf;
}

}  // namespace

std::string fused_temperature(const char* name, double t_C, double sd_K, std::int8_t source, double observed_age_s) {
  char how[48];
  if (source == mirror::estimate_t::SOURCE_OBSERVED) {
    std::snprintf(how, sizeof how, "observed");
  } else if (observed_age_s >= 0.0) {
    std::snprintf(how, sizeof how, "predicted, observed %.0f s ago", observed_age_s);
  } else {
    std::snprintf(how, sizeof how, "predicted, never observed");
  }
  char buf[128];
  std::snprintf(buf, sizeof buf, "%s %.1f C sd %.1f K %s", name, t_C, sd_K, how);
  return buf;
}

std::string status_line(const EstimateReport& r, const SourceReport& source) {
  static const char* kStates[] = {"starting", "running", "STALE", "stopping"};
  char head[256];
  std::snprintf(head, sizeof head,
                "rpemd %-8s n=%+.3f pu  psi_m=%.4f Wb%s (T_magnet %5.1f C)  r_s=%.4f Ohm%s (T_winding %5.1f C)",
                kStates[static_cast<std::uint8_t>(r.state)], r.speed_pu, r.psi_m_Wb,
                mark(r.psi_m_adapting, r.psi_m_age_s, r.psi_m_valid).c_str(), r.t_magnet_C, r.r_s_Ohm,
                mark(r.r_s_adapting, r.r_s_age_s, r.r_s_valid).c_str(), r.t_winding_C);
  std::string line = head;
  if (r.thermal_active) {
    line += "  " + fused_temperatures(r);
  }
  if (source.has_truth) {
    char truth[128];
    std::snprintf(truth, sizeof truth, "  [sim truth %.4f Wb %.4f Ohm, T_magnet %.1f C T_winding %.1f C]",
                  source.truth_psi_m_Wb, source.truth_r_s_Ohm, source.truth_t_magnet_C, source.truth_t_winding_C);
    line += truth;
  }
  if (const DiagnosticsRows& s = source.rows; s.get(&rpem::diagnostics_t::vesc_polls) >= 0) {
    using D = rpem::diagnostics_t;
    char vesc[192];
    std::snprintf(
        vesc, sizeof vesc, "  [vesc polls %lld replies %lld timeouts %lld late %lld unrequested %lld stolen_reads %lld]",
        static_cast<long long>(s.get(&D::vesc_polls)), static_cast<long long>(s.get(&D::vesc_replies)),
        static_cast<long long>(s.get(&D::vesc_timeouts)), static_cast<long long>(s.get(&D::vesc_late_replies)),
        static_cast<long long>(s.get(&D::vesc_unrequested_replies)), static_cast<long long>(s.get(&D::vesc_stolen_reads)));
    line += vesc;
  }
  if (r.frozen) line += "  FROZEN";
  return line;
}

}  // namespace rpem::daemon
