#pragma once
// The two non-finite doubles the code names: +∞ (an open bound, "no limit") and a quiet NaN ("no value").
// Defined once here: files that each defined their own clashed when compiled together (RPEM_UNITY_BUILD).

#include <limits>

namespace rpem::core {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace rpem::core
