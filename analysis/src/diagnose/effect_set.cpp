// EffectSet (effect_fit.hpp): the calibrated constants and the effects a fit moves, and the model they make.
#include <algorithm>
#include <cmath>

#include "rpem/analysis/diagnose/effect_fit.hpp"

namespace rpem::analysis {

bool identified(const EffectSet& set, const CalibrationIntervals& ci, std::size_t i) {
  return ci.half_width[i] <= kIdentifiedHalfWidth && std::abs(set.calibration[i]) < 0.99 * kCalibrationBound;
}

double misfit_norm_A(std::size_t training_samples, double heldout_rms_A, double noise_floor_A) {
  if (heldout_rms_A <= noise_floor_A) return 0.0;
  return std::sqrt(static_cast<double>(training_samples) * (heldout_rms_A * heldout_rms_A - noise_floor_A * noise_floor_A));
}

Identification identification(const EffectSet& set, const CalibrationIntervals& ci, std::size_t i, double misfit_A) {
  if (identified(set, ci, i)) return Identification::kNarrow;
  if (!(std::abs(set.calibration[i]) < 0.99 * kCalibrationBound)) return Identification::kNot;
  // The configured value θ_c outside θ̂·(1 ± (h + m)), with θ̂ = θ_c·(1 + s·δ): |s·δ| > (h + m)·(1 + s·δ).
  const double moved = kCalibrationScale * set.calibration[i];
  const double widened = ci.half_width[i] + ci.change_per_A[i] * misfit_A;
  return std::abs(moved) > widened * (1.0 + moved) ? Identification::kRejectsConfiguration : Identification::kNot;
}

ExtendedModel EffectSet::model(const EffectContext& c) const {
  ExtendedModel m = c.base;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    m.machine.*kCalibratedFields[i] *= 1.0 + kCalibrationScale * calibration[i];
  }
  for (std::size_t j = 0; j < effects.size(); ++j) effects[j].row->apply(effects[j], parameters[j].data(), c, m);
  return m;
}

EffectSet EffectSet::with(const Effect& e, const EffectContext&, const std::vector<double>& start) const {
  EffectSet s = *this;
  if (e.row->fitted_constant() >= 0) s.calibrated[static_cast<std::size_t>(e.row->fitted_constant())] = true;
  s.effects.push_back(e);
  s.parameters.push_back(start.empty() ? std::vector<double>(static_cast<std::size_t>(e.row->parameters), 0.0) : start);
  return s;
}

EffectSet EffectSet::without(const Effect& e) const {
  EffectSet s = *this;
  s.effects.clear();
  s.parameters.clear();
  for (std::size_t j = 0; j < effects.size(); ++j) {
    if (effects[j] == e) continue;
    s.effects.push_back(effects[j]);
    s.parameters.push_back(parameters[j]);
  }
  return s;
}

bool EffectSet::contains(const Effect& e) const { return std::find(effects.begin(), effects.end(), e) != effects.end(); }

int EffectSet::free_calibration() const { return static_cast<int>(std::count(calibrated.begin(), calibrated.end(), true)); }

double BlockScores::total() const {
  double t = 0.0;
  for (double s : ssr) t += s;
  return t;
}

}  // namespace rpem::analysis
