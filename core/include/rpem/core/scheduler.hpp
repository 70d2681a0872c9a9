#pragma once
// Speed-dependent gain scheduling (eq:GainSchedule) and projection onto D_M (eq:paramsubset).

#include <cmath>
#include <cstdint>

#include "rpem/core/types.hpp"

namespace rpem::core {

/// eq:GainSchedule limits, |n_lim,1| ≥ |n_lim,2|.
struct SchedulerConfig {
  double psi_m_min_speed_pu = 0.0;  ///< n_lim,1: ψ̂m adapts only where |n| > n_lim,1
  double r_s_max_speed_pu = 0.0;    ///< n_lim,2: r̂s adapts only where |n| < n_lim,2
};

/// Which parameters may adapt in this sample.
struct Schedule {
  bool psi_m = false;
  bool r_s = false;
};

/// eq:GainSchedule. The speed is the mean over the prediction interval.
[[nodiscard]] inline Schedule schedule(const SchedulerConfig& c, double n_pu) noexcept {
  const double speed = std::abs(n_pu);
  return {speed > c.psi_m_min_speed_pu, speed < c.r_s_max_speed_pu};
}

/// Zeroes the gain rows of parameters that may not adapt.
inline void apply_schedule(const Schedule& s, Mat2& gain) noexcept {
  // A row mask, each column selected in registers and written whole: Mat2 is column-major, and zeroing
  // a row element-wise (as Eigen's select() compiles) made the next whole-column loads wait on scalar
  // stores (store-forwarding stalls on the per-sample path). A select, not a product: a row that may not
  // adapt is zero even where its gain is not finite.
  gain.col(0) = Vec2(s.psi_m ? gain(0, 0) : 0.0, s.r_s ? gain(1, 0) : 0.0);
  gain.col(1) = Vec2(s.psi_m ? gain(0, 1) : 0.0, s.r_s ? gain(1, 1) : 0.0);
}

/// D_M of eq:paramsubset.
struct ParameterBounds {
  Vec2 min_pu = Vec2::Zero();
  Vec2 max_pu = Vec2::Zero();
};

/// Projection of parameter j's value onto its interval of D_M. Returns whether it was clamped.
[[nodiscard]] inline bool project(const ParameterBounds& b, int j, double& value) noexcept {
  if (value < b.min_pu[j]) {
    value = b.min_pu[j];
    return true;
  }
  if (value > b.max_pu[j]) {
    value = b.max_pu[j];
    return true;
  }
  return false;
}

/// Projection of one parameter onto its interval of D_M. Returns whether it was clamped.
[[nodiscard]] inline bool project(const ParameterBounds& b, Vec2& theta, int j) noexcept { return project(b, j, theta[j]); }

/// Projection onto the box D_M (the Euclidean projection of a box is the clamp). Returns a bit per
/// parameter that was clamped (bit kPsiM, bit kRs).
[[nodiscard]] inline std::uint8_t project(const ParameterBounds& b, Vec2& theta) noexcept {
  std::uint8_t clamped = 0;
  for (int j = 0; j < 2; ++j) clamped |= static_cast<std::uint8_t>(static_cast<unsigned>(project(b, theta, j)) << j);
  return clamped;
}

}  // namespace rpem::core
