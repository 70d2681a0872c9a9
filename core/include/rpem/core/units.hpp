#pragma once
// Conversions between units of the same quantity: revolutions per minute ↔ radians per second (speeds,
// mechanical or electrical alike: pole pairs are the caller's). Per-unit values are another matter,
// converted with a machine's base in per_unit.hpp, which uses these for its rated speed.

#include "rpem/core/types.hpp"

namespace rpem::core {

inline constexpr double kRadPerSPerRpm = 2.0 * kPi / 60.0;    ///< 1 rpm in rad/s
inline constexpr double kRpmPerRadPerS = 60.0 / (2.0 * kPi);  ///< 1 rad/s in rpm

[[nodiscard]] constexpr double rpm_to_rad_s(double n_rpm) noexcept { return n_rpm * kRadPerSPerRpm; }
[[nodiscard]] constexpr double rad_s_to_rpm(double omega_rad_s) noexcept { return omega_rad_s * kRpmPerRadPerS; }

}  // namespace rpem::core
