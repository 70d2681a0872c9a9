#pragma once
// The median of a sample, shared by the log's sampling statistics (diagnose/log_data.cpp), the verdict's noise
// floor (diagnose/verdict.cpp) and the thermal fit's typical operating point (thermal/network_layout.cpp).
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

}  // namespace rpem::analysis
