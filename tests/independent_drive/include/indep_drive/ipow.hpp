#pragma once
// An integer power, shared by the flux map's reader (flux_map.cpp) and the polynomial flux model (flux_model.cpp).

namespace indep {

/// x^k for small non-negative k, with x^0 = 1 (also for x = 0) and x^(−1) unused (multiplied by 0).
inline double ipow(double x, int k) {
  double r = 1.0;
  for (int j = 0; j < k; ++j) r *= x;
  return r;
}

}  // namespace indep
