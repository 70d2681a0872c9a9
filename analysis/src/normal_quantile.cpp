#include "rpem/analysis/normal_quantile.hpp"

#include <cassert>
#include <cmath>

namespace rpem::analysis {

double upper_normal_quantile(double p) {
  assert(p > 0.0 && p < 0.5);
  double lo = 0.0, hi = 40.0;  // Φ(−40) ≈ 4·10⁻³⁵⁰, below any double p
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;  // Φ(−z) = erfc(z/√2)/2
  }
  return 0.5 * (lo + hi);
}

}  // namespace rpem::analysis
