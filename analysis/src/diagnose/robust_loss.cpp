#include "rpem/analysis/diagnose/robust_loss.hpp"

#include <ceres/loss_function.h>

#include <algorithm>
#include <cassert>
#include <cmath>

namespace rpem::analysis {
namespace {

/// The median of χ²₂ (2·ln 2): |r|²/σ² of a two-component Gaussian lies below it half the time.
constexpr double kMedianChiSquare2 = 1.3862943611198906;

/// P(X ≥ n) for X ~ Poisson(1).
double poisson1_upper_tail(std::size_t n) {
  double below = 0.0, term = std::exp(-1.0);  // P(X = 0)
  for (std::size_t j = 0; j < n; ++j) {
    below += term;
    term /= static_cast<double>(j + 1);
  }
  return std::max(0.0, 1.0 - below);
}

}  // namespace

OutlierTest test_outliers(const std::vector<double>& residuals) {
  assert(residuals.size() % 2 == 0);
  OutlierTest t;
  t.samples = residuals.size() / 2;
  if (t.samples < 3) return t;
  std::vector<double> s(t.samples);
  for (std::size_t k = 0; k < t.samples; ++k)
    s[k] = residuals[2 * k] * residuals[2 * k] + residuals[2 * k + 1] * residuals[2 * k + 1];
  std::vector<double> sorted = s;
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(t.samples / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  t.scale_A = std::sqrt(*mid / kMedianChiSquare2);
  if (!(t.scale_A > 0.0)) return t;
  t.threshold_A = t.scale_A * std::sqrt(2.0 * std::log(static_cast<double>(t.samples)));
  const double b2 = t.threshold_A * t.threshold_A;
  t.beyond = static_cast<std::size_t>(std::count_if(s.begin(), s.end(), [&](double v) { return v > b2; }));
  t.p_value = poisson1_upper_tail(t.beyond);
  t.outliers = t.p_value <= kOutlierP;
  return t;
}

double RobustLoss::rho(double s) const {
  if (!robust()) return s;
  double out[3];
  ceres::HuberLoss(threshold_A).Evaluate(s, out);
  return out[0];
}

double RobustLoss::residual_scale(double s) const {
  if (!robust() || s <= threshold_A * threshold_A) return 1.0;
  return std::sqrt(rho(s) / s);
}

}  // namespace rpem::analysis
