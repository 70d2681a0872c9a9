#pragma once
// Fitting effects to a log: the parameters of a set of effects minimise the training blocks' squared
// residuals of the replay (nonlinear least squares, Ceres, forward differences through the whole
// replay); the held-out blocks judge the result. Screening ranks candidates cheaply by the first
// Gauss–Newton step: the reduction r₀ᵀJ(JᵀJ)⁻¹Jᵀr₀ of the training sum of squares it predicts.

#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/replay.hpp"

namespace rpem::analysis {

/// A set of effects with their scaled parameters.
struct EffectSet {
  std::vector<Effect> effects;
  std::vector<std::vector<double>> parameters;

  [[nodiscard]] ExtendedModel model(const EffectContext& c) const;
  [[nodiscard]] EffectSet with(const Effect& e, const EffectContext& c) const;  ///< plus `e` at its nominal (zero) parameters
  [[nodiscard]] bool contains(const Effect& e) const;
};

struct BlockScores {
  std::vector<double> ssr;  ///< per held-out block, A²
  std::size_t samples = 0;
  [[nodiscard]] double total() const;
};

class EffectFitter {
 public:
  EffectFitter(const ModelReplay& replay, const EffectContext& context);

  /// Fits every parameter of `start` jointly from its values; returns the fitted set.
  [[nodiscard]] EffectSet fit(const EffectSet& start) const;

  /// Training sum of squares `base` would lose, to first order, by adding `candidate`.
  [[nodiscard]] double screen(const EffectSet& base, const Effect& candidate) const;

  /// Training sum of squares [A²].
  [[nodiscard]] double training_ssr(const EffectSet& set) const;
  /// Sums of squares per held-out block.
  [[nodiscard]] BlockScores heldout(const EffectSet& set) const;

  [[nodiscard]] const ModelReplay& replay() const noexcept { return replay_; }
  [[nodiscard]] const EffectContext& context() const noexcept { return context_; }

  /// The training residuals of a set, d and q interleaved (fixed length).
  void training_residuals(const EffectSet& set, std::vector<double>& out) const;

 private:
  const ModelReplay& replay_;
  EffectContext context_;
  std::vector<std::size_t> training_;  ///< samples with a prediction in training blocks (nominal replay)
};

}  // namespace rpem::analysis
