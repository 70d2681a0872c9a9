#include "rpem/analysis/diagnose/outliers.hpp"

#include <cmath>

namespace rpem::analysis {

OutlierCheck check_outliers(const EffectFitter& least_squares, const EffectSet& fitted, const CalibrationIntervals& ci) {
  OutlierCheck c;
  std::vector<double> r;
  least_squares.training_residuals(fitted, r);
  c.test = test_outliers(r);
  if (!c.test.outliers || (fitted.free_calibration() == 0 && fitted.effects.empty())) return c;

  // Huber's M-estimate with the scale re-estimated from its own residuals (b from the least-squares fit's
  // median is inflated where the outliers pulled it).
  c.loss.threshold_A = c.test.threshold_A;
  EffectSet robust = fitted;
  for (int i = 0; i < kScaleIterations; ++i) {
    robust = least_squares.with_loss(c.loss).fit(robust);
    least_squares.training_residuals(robust, r);
    const OutlierTest t = test_outliers(r);
    const double previous = c.loss.threshold_A;
    c.loss.threshold_A = t.threshold_A;
    c.test.beyond = t.beyond;
    c.test.p_value = t.p_value;
    c.test.scale_A = t.scale_A;
    if (std::abs(previous / t.threshold_A - 1.0) < 0.1) break;
  }
  c.test.threshold_A = c.loss.threshold_A;

  auto consider = [&](double shift, const std::string& name) {
    if (shift > c.largest_shift) {
      c.largest_shift = shift;
      c.parameter = name;
    }
  };
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (!fitted.calibrated[i] || !(ci.half_width[i] > 0.0)) continue;
    const double moved = kCalibrationScale * (robust.calibration[i] - fitted.calibration[i]) /
                         (1.0 + kCalibrationScale * fitted.calibration[i]);
    consider(std::abs(moved) / ci.half_width[i], kCalibrated[i]);
  }
  for (std::size_t j = 0; j < fitted.effects.size(); ++j) {
    for (std::size_t p = 0; p < fitted.parameters[j].size(); ++p) {
      const double hw = ci.effect_half_width[j][p];
      if (!(hw > 0.0)) continue;
      consider(std::abs(robust.parameters[j][p] - fitted.parameters[j][p]) / hw,
               fitted.effects[j].label() + " parameter " + std::to_string(p + 1));
    }
  }
  c.influential = c.largest_shift > 1.0;
  return c;
}

}  // namespace rpem::analysis
