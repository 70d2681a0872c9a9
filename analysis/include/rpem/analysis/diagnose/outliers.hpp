#pragma once
// Whether outliers that remain after the least-squares diagnosis move its fit (docs/diagnose.md, "Outliers
// and the robust loss"). A model misfit is rarely Gaussian — the residual of a model still missing a small
// effect, or of a bench's cold start, has heavy tails — so samples beyond the Gaussian level b alone do not
// make a log's least-squares fit wrong: every example and test log has some. What matters is whether they
// move it. The final model's free parameters (calibrated constants and effect parameters) are refitted
// under Huber's loss at b, b re-estimated from the refit's residuals until it settles (within 10 %, at most
// kScaleIterations times); if some parameter moves by more than its cluster-robust 95 % half-width, the
// least-squares value lies outside the interval the data give it and the tail decided it — a Hausman-type
// comparison of an efficient and a robust estimator, which agree where nothing is contaminated. Then the
// whole diagnosis (calibration and selection) is run again under the robust loss, b re-estimated from its
// final residuals and the diagnosis repeated until b settles (at most kRobustRuns).

#include <array>
#include <string>

#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/diagnose/robust_loss.hpp"

namespace rpem::analysis {

/// Refits of the scale at most (the check's Huber refits of the final model).
inline constexpr int kScaleIterations = 4;
/// Robust diagnoses at most, b re-estimated from each one's final residuals (diagnosis.cpp).
inline constexpr int kRobustRuns = 3;

struct OutlierCheck {
  OutlierTest test;            ///< of the final least-squares model's training residuals
  RobustLoss loss;             ///< Huber at the settled threshold (set where test.outliers; the robust runs' last)
  int robust_runs = 0;         ///< robust diagnoses run (0: least squares stood)
  double largest_shift = 0.0;  ///< max over the free parameters of |θ_Huber − θ_LS| / its 95 % half-width
  std::string parameter;       ///< whose shift that is (a constant's key, or "effect:index")
  bool influential = false;    ///< largest_shift > 1: the diagnosis is run again under `loss`
};

/// `least_squares`: the fitter the diagnosis ran with; `fitted`, `ci`: its final model and intervals.
[[nodiscard]] OutlierCheck check_outliers(const EffectFitter& least_squares, const EffectSet& fitted,
                                          const CalibrationIntervals& ci);

}  // namespace rpem::analysis
