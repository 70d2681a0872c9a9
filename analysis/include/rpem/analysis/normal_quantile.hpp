#pragma once
// The standard normal's upper quantile, for the tools' tests at a stated false rate.

namespace rpem::analysis {

/// z with Φ(−z) = p, for 0 < p < 1/2: bisection on erfc to 10⁻¹² (p down to the smallest double).
[[nodiscard]] double upper_normal_quantile(double p);

}  // namespace rpem::analysis
