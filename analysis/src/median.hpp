#pragma once
// The median and quantiles of a sample, shared by the log's sampling statistics (diagnose/log_data.cpp), the
// verdict's noise floor (diagnose/verdict.cpp), a temperature column's span (diagnose/effects.cpp) and the thermal
// fit's typical operating point and observed temperatures (thermal/).
#include <algorithm>
#include <cstddef>
#include <vector>

namespace rpem::analysis {

/// The median of v (of an even count the upper middle value); 0 for an empty v.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The q-quantile of v (0 ≤ q ≤ 1): the element of rank ⌊q·(n − 1)⌋ in ascending order; 0 for an empty v.
inline double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto at = v.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

}  // namespace rpem::analysis
