#pragma once
// sin(x)/x: the length of a vector's mean over a hold during which it turns by 2x (docs/derivations.md §11,
// "Reported command"), by the series 1 − x²/6 near 0, whose next term x⁴/120 is below a double's resolution there.

#include <cmath>

namespace rpem::core {

[[nodiscard]] inline double sinc(double x) noexcept { return std::abs(x) < 1e-4 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

}  // namespace rpem::core
