#pragma once
// The supervisory controller's configuration (docs/supervisor.md, "Configuration"), from YAML:
//     supervisor:
//       rated_current_A: 120
//       magnet:  {warning_C: 100, limit_C: 140, floor_A: 30, raw_sd_K: 4, max_rate_K_s: 0.05}
//       winding: {warning_C: 120, limit_C: 150, floor_A: 30, raw_sd_K: 2.5, max_rate_K_s: 0.5}
//       freshness: {max_age_s: 0.5, max_skew_s: 0.05}
// Every key required, ranges checked, unknown keys refused (io::ConfigError: file:line:column).

#include <string>

#include "rpem/supervisor/derating.hpp"
#include "rpem/supervisor/estimate_gate.hpp"

namespace rpem::supervisor {

struct Config {
  double rated_current_A = 0.0;  ///< I_r
  PartLimits magnet, winding;
  Freshness freshness;
};

/// Reads and checks a configuration file; throws io::ConfigError naming file, line and key.
[[nodiscard]] Config load_config(const std::string& path);

}  // namespace rpem::supervisor
