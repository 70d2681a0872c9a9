#pragma once
// What the io fuzz targets assert of every estimate the estimator gives on what a reader accepted: finite and inside
// D_M, the configured bounds, to rounding (the estimator projects in pu, and the SI value carries the conversion's
// rounding).

#include <cmath>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/settings.hpp"

namespace rpem::fuzz {

[[nodiscard]] inline bool inside_to_rounding(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
}

[[nodiscard]] inline bool estimate_in_bounds(const core::Estimate& e, const core::EstimatorSettings& s) {
  return inside_to_rounding(e.psi_m_Wb, s.psi_m_min_Wb, s.psi_m_max_Wb) &&
         inside_to_rounding(e.r_s_Ohm, s.r_s_min_Ohm, s.r_s_max_Ohm);
}

}  // namespace rpem::fuzz
