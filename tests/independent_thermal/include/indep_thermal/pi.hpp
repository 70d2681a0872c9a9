#pragma once
// π, written out here (the independent plant shares no code with the product, not even its kPi), once for all
// the plant's files.

namespace indep_thermal {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace indep_thermal
