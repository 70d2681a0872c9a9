#include "rpem/supervisor/derating.hpp"

#include <cmath>

namespace rpem::supervisor {

double upper_bound_C(const PartLimits& part, const TemperatureEstimate& t) noexcept {
  return t.t_C + 2.0 * t.sd_K + part.max_rate_K_s * t.unrenewed_s;
}

double part_current_A(const PartLimits& part, double rated_current_A, std::optional<double> t_upper_C) noexcept {
  if (!t_upper_C || !std::isfinite(*t_upper_C)) return part.floor_A;  // unknown: at the limit
  const double t = *t_upper_C;
  if (t <= part.warning_C) return rated_current_A;
  if (t > part.limit_C) return 0.0;
  return rated_current_A - (rated_current_A - part.floor_A) * (t - part.warning_C) / (part.limit_C - part.warning_C);
}

}  // namespace rpem::supervisor
