#pragma once
// EffectFitter::over_training (effect_fit.hpp), shared by the fits (effect_fit.cpp) and the screening
// (screening.cpp).
#include <cassert>

#include "rpem/analysis/diagnose/effect_fit.hpp"

namespace rpem::analysis {

/// A sample a model predicts nothing finite at counts as this large a miss on each axis rather than vanishing.
inline constexpr double kMiss_A = 1e3;

/// Forward-difference step on the scaled parameters (1 = a typical magnitude): the intervals' and the screening's
/// absolute step, and the fit's relative one (Ceres' relative_step_size, with its floor √ε).
inline constexpr double kDifferenceStep = 1e-3;

template <class Acc, class Add>
std::vector<Acc> EffectFitter::over_training(const std::vector<ExtendedModel>& models, const Acc& init,
                                             const Add& add) const {
  return over_training_from(models, std::vector<Acc>(training_blocks_.size(), init), add);
}

template <class Acc, class Add>
std::vector<Acc> EffectFitter::over_training_from(const std::vector<ExtendedModel>& models, std::vector<Acc> out,
                                                  const Add& add) const {
  assert(out.size() == training_blocks_.size());
  replay_.for_blocks(training_blocks_, [&](std::size_t i, int b) {
    Acc& acc = out[i];
    std::vector<core::Vec2> r(models.size());
    const bool robust = loss_.robust();
    replay_.replay_block(b, models, [&](std::size_t k, std::span<const ModelSample> m) {
      if (!fitted_[k]) return;
      for (std::size_t j = 0; j < m.size(); ++j) {
        r[j] = m[j].valid ? m[j].residual_A : core::Vec2::Constant(kMiss_A);
        if (robust) r[j] *= loss_.residual_scale(r[j].squaredNorm());  // |r|² becomes ρ(|r|²) (robust_loss.hpp)
      }
      add(acc, std::span<const core::Vec2>(r));
    });
  });
  return out;
}

}  // namespace rpem::analysis
