#pragma once
// Outliers in a fit's residuals and the loss that bounds their influence (docs/diagnose.md, "Outliers and
// the robust loss"). A residual sample the model cannot represent at all — a row the bridge did not
// modulate, a frame the angle was not locked in, a glitch — lies far outside the residual's bulk, and under
// least squares its square pulls every constant and effect towards it. The bulk's per-component scale σ̂
// comes from the median of |r|² (for a two-component Gaussian |r|²/σ² is χ²₂, median 2·ln 2); the level
// b = σ̂·√(2·ln N) is where a Gaussian sample of N lies beyond once in expectation (P(|r| > b) =
// exp(−b²/2σ̂²) = 1/N), and the count beyond it against that one (Poisson(1)) says whether the tail is
// heavier than Gaussian (p ≤ kOutlierP). Whether such a tail moves the fit is outliers.hpp's question; where
// it does, every fit and comparison minimises Σ ρ(|r_k|²) with Huber's ρ at b (ceres::HuberLoss): the
// squares up to b, linear beyond, so a sample beyond b weighs no more than one at b, and residuals within b
// count exactly as under least squares.

#include <cstddef>
#include <limits>
#include <vector>

namespace rpem::analysis {

/// Significance at which the samples beyond b are more than a Gaussian bulk explains.
inline constexpr double kOutlierP = 1e-3;

/// The outlier test of one set of residuals.
struct OutlierTest {
  std::size_t samples = 0;                                       ///< residual vectors tested
  double scale_A = 0.0;                                          ///< σ̂, per component, from the median of |r|²
  double threshold_A = std::numeric_limits<double>::infinity();  ///< b = σ̂·√(2·ln N)
  std::size_t beyond = 0;                                        ///< samples with |r| > b (1 expected)
  double p_value = 1.0;                                          ///< P(Poisson(1) ≥ beyond)
  bool outliers = false;                                         ///< p_value ≤ kOutlierP
};

/// `residuals`: d and q interleaved (EffectFitter::training_residuals' layout).
[[nodiscard]] OutlierTest test_outliers(const std::vector<double>& residuals);

/// The loss every fit minimises, Σ ρ(|r_k|²) over the samples: least squares (ρ(s) = s) or Huber's at a
/// threshold b (ρ(s) = s for s ≤ b², 2·b·√s − b² beyond).
struct RobustLoss {
  double threshold_A = std::numeric_limits<double>::infinity();  ///< infinite: least squares

  [[nodiscard]] bool robust() const noexcept { return threshold_A < std::numeric_limits<double>::infinity(); }
  /// ρ(s) for a squared residual norm s [A²].
  [[nodiscard]] double rho(double s) const;
  /// The factor √(ρ(s)/s) that scales a residual vector so that its squared norm is ρ(s): least squares on
  /// the scaled residuals minimises Σ ρ.
  [[nodiscard]] double residual_scale(double s) const;
};

}  // namespace rpem::analysis
