#pragma once
// One-dimensional minimisation for the thermal fit's scalar choices (noises, time constants).

#include <cmath>

namespace rpem::analysis {

/// The minimum of a unimodal `f` on [a, b] by golden-section search, to a bracket narrower than `tolerance`:
/// the bracket's middle.
template <class F>
double golden_section_minimum(F&& f, double a, double b, double tolerance) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  while (b - a > tolerance) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1;
      x1 = b - g * (b - a), f1 = f(x1);
    } else {
      a = x1, x1 = x2, f1 = f2;
      x2 = a + g * (b - a), f2 = f(x2);
    }
  }
  return 0.5 * (a + b);
}

}  // namespace rpem::analysis
