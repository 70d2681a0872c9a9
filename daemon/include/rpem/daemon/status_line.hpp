#pragma once
// rpemd's status line on stdout, one per status_interval_s (docs/rpemd.md, "The status line"): the state, the
// speed, each parameter with its mark and the temperature derived from it; with a thermal network both fused
// temperatures with their σ and how each stands (observed now, or predicted since its last observation); the
// simulated drive's truth; a VESC source's poll counters. Printed by the publisher thread, never the loop.

#include <cstdint>
#include <string>

#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/source.hpp"

namespace rpem::daemon {

/// The line for the newest estimate and the source's newest report, without its newline.
[[nodiscard]] std::string status_line(const EstimateReport& r, const SourceReport& source);

/// One fused temperature as RPEM_ESTIMATE carries it (core::ThermalNodeReport's fields): "T_magnet 61.2 C sd 3.1 K
/// observed", "… predicted, observed 40 s ago" or "… predicted, never observed".
[[nodiscard]] std::string fused_temperature(const char* name, double t_C, double sd_K, std::int8_t source,
                                            double observed_age_s);

/// "fused: T_magnet …, T_winding …" for an estimate whose thermal network has stepped (thermal_active): the status
/// line's and `rpem listen`'s words for the same fields of EstimateReport or the decoded rpem::estimate_t.
template <class Estimate>
[[nodiscard]] std::string fused_temperatures(const Estimate& m) {
  return "fused: " +
         fused_temperature("T_magnet", m.t_magnet_fused_C, m.t_magnet_fused_sd_C, m.t_magnet_source,
                           m.t_magnet_observed_age_s) +
         ", " +
         fused_temperature("T_winding", m.t_winding_fused_C, m.t_winding_fused_sd_C, m.t_winding_source,
                           m.t_winding_observed_age_s);
}

}  // namespace rpem::daemon
