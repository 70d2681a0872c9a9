#pragma once
// Fitting effects to a log: the baseline's calibrated constants and the parameters of a set of effects
// minimise the training blocks' squared residuals of the replay (nonlinear least squares, Ceres, forward
// differences through the replay of the training blocks); the held-out blocks judge the result.
// Screening ranks candidates cheaply by the first Gauss–Newton step: the reduction r₀ᵀJ(JᵀJ)⁻¹Jᵀr₀ of
// the training sum of squares it predicts, with the columns of the calibrated constants and of the effects
// already in the model in J, so that what they already explain is not credited to a candidate, and what
// they took of the candidate's residual while it was missing is.
//
// Nothing here holds a residual per sample (docs/diagnose.md, "Long recordings") but a fit's last cost-only
// evaluation's training residuals, which the Jacobian Ceres asks for at the same point next takes as its base
// point's instead of replaying them again. Every quantity is a sum
// over the samples — JᵀJ, Jᵀr, rᵀr, the blocks' scores — accumulated as the models stream through a block
// together, block by block on the replay's pool, and added in block order. Ceres is handed the fit in the
// same reduced form: the least-squares problem ‖J·δ + r‖² over the training samples equals ‖R_J·δ + R_r‖²
// with [R_J R_r] the triangular factor of the QR decomposition of [J r] (Householder over a few rows at a
// time, then over the blocks' factors), so its trust-region steps are those of the whole problem, from P + 1
// residuals instead of two per sample. The Jacobian's columns are the forward differences Ceres' own
// numeric differentiation takes (step max(√ε, 10⁻³·|θ|)), from the same replays. Under a robust loss
// (robust_loss.hpp) each sample's residual vector is scaled by √(ρ(|r|²)/|r|²) before it enters any of these
// sums, so every fit, screening and interval minimises or linearises Σ ρ.

#include <array>
#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/replay.hpp"
#include "rpem/analysis/diagnose/robust_loss.hpp"

namespace rpem::analysis {

/// The baseline's calibrated constants and a set of effects with their scaled parameters.
struct EffectSet {
  std::array<double, kCalibrated.size()> calibration{};  ///< relative changes, scaled (1 = 1 %)
  std::array<bool, kCalibrated.size()> calibrated{};     ///< which the fits may move (identifiable)
  std::vector<Effect> effects;
  std::vector<std::vector<double>> parameters;

  [[nodiscard]] ExtendedModel model(const EffectContext& c) const;
  /// Plus `e` at `start` (its zero parameters if empty).
  [[nodiscard]] EffectSet with(const Effect& e, const EffectContext& c, const std::vector<double>& start = {}) const;
  [[nodiscard]] EffectSet without(const Effect& e) const;
  [[nodiscard]] bool contains(const Effect& e) const;
  [[nodiscard]] int free_calibration() const;
};

struct BlockScores {
  std::vector<double> ssr;  ///< per held-out block, A²
  std::size_t samples = 0;
  [[nodiscard]] double total() const;
};

/// The calibrated constants' 95 % intervals (docs/diagnose.md, "The calibrated baseline").
struct CalibrationIntervals {
  /// Cluster-robust over the training blocks (sandwich (JᵀJ)⁻¹·(Σ_b J_bᵀr_b r_bᵀJ_b)·(JᵀJ)⁻¹), relative.
  std::array<double, kCalibrated.size()> half_width{};
  /// What the log's excitation alone allows (σ²·(JᵀJ)⁻¹ with σ the noise floor), relative.
  std::array<double, kCalibrated.size()> excitation_half_width{};
  /// √((JᵀJ)⁻¹ₖₖ), relative: the change of constant k, the others refitted, that moves the model's training
  /// currents by 1 A in Euclidean norm over all samples (the excitation's half-width is z·σ times it). Times a
  /// misfit |e| it is the largest bias that misfit could put into the constant (Cauchy–Schwarz on
  /// Δθ = (JᵀJ)⁻¹Jᵀe): the model mismatch allowance (misfit_norm_A).
  std::array<double, kCalibrated.size()> change_per_A{};
  /// The effects' scaled parameters, cluster-robust (same order as the set's).
  std::vector<std::vector<double>> effect_half_width;
};

/// A calibrated constant is identifiable when the log's excitation alone (its noise floor and the
/// replay's sensitivity to the constant) pins it within this relative 95 % half-width …
inline constexpr double kIdentifiableHalfWidth = 0.01;
/// … and its fit is pinned within this one by the cluster-robust interval (which the model's own errors
/// widen), away from the ±50 % bound — at the calibrated baseline and with every effect named.
inline constexpr double kIdentifiedHalfWidth = 0.1;

/// Whether the fitted constant i (kCalibrated order) of `set` is identified by these intervals (narrow).
[[nodiscard]] bool identified(const EffectSet& set, const CalibrationIntervals& ci, std::size_t i);

/// The misfit a model leaves above the noise floor, as a norm over the N training samples [A]:
/// |e| = √(N·(rms² − floor²)) with rms its held-out RMS (0 at or below the floor; floor 0 where unknown: the
/// whole residual may be misfit). The model mismatch allowance of constant k is change_per_A[k]·|e|.
[[nodiscard]] double misfit_norm_A(std::size_t training_samples, double heldout_rms_A, double noise_floor_A);

/// Why the calibration keeps a fitted constant.
enum class Identification {
  kNot,                   ///< at the bound, or its configured value within the interval widened by the allowance
  kNarrow,                ///< identified(): its cluster-robust interval within ±kIdentifiedHalfWidth
  kRejectsConfiguration,  ///< a wider interval, but the configured value lies outside it widened by the allowance
};

/// The calibration's rule (docs/diagnose.md, "Calibrated despite a large mismatch"): a constant the log's
/// excitation admits is calibrated when identified() — or, its interval wider, when the log rejects the
/// configured value even granting the model's misfit its largest bias: the configured value lies outside the
/// cluster-robust interval widened by the mismatch allowance, exactly where the report states the
/// configuration off (calibration_findings). Away from the ±50 % bound in both cases.
/// `misfit_A`: misfit_norm_A of the set.
[[nodiscard]] Identification identification(const EffectSet& set, const CalibrationIntervals& ci, std::size_t i,
                                            double misfit_A);

/// A round's screening: for each candidate, its best start and the training gain the screening credits it
/// with from there.
struct Screening {
  double ssr = 0.0;                         ///< training sum of squares of the round's model [A²]
  std::vector<std::vector<double>> starts;  ///< per candidate (scaled, clamped to its bounds)
  std::vector<double> gain;                 ///< per candidate [A²]
};

class EffectFitter {
 public:
  EffectFitter(const ModelReplay& replay, const EffectContext& context);

  /// The same fitter minimising `loss` (robust_loss.hpp) in every fit, screening, interval and held-out
  /// score: each sample's residual vector is scaled by √(ρ(|r|²)/|r|²), so that its squared norm is ρ.
  [[nodiscard]] EffectFitter with_loss(const RobustLoss& loss) const;
  [[nodiscard]] const RobustLoss& loss() const noexcept { return loss_; }

  /// Fits every free parameter of `start` jointly from its values; returns the fitted set (and, if
  /// asked, its training sum of squares).
  [[nodiscard]] EffectSet fit(const EffectSet& start, double* training_ssr = nullptr) const;

  /// Screens `candidates` against `base`: each one's best start (of its row's starts: the lowest training
  /// sum of squares there, the base's free constants and effects moved to their best by the linear step
  /// of their columns) and the training sum of squares `base` would lose, to first order, by adding it
  /// there — with those columns moving too.
  [[nodiscard]] Screening screen(const EffectSet& base, const std::vector<Effect>& candidates) const;

  /// Training sum of ρ(|r|²) [A²] (the sum of squares under least squares).
  [[nodiscard]] double training_ssr(const EffectSet& set) const;
  /// Sums of ρ(|r|²) per held-out block (sums of squares under least squares).
  [[nodiscard]] BlockScores heldout(const EffectSet& set) const;

  /// The calibrated constants' intervals for a fitted set; `noise_floor_A` scales the excitation's.
  [[nodiscard]] CalibrationIntervals intervals(const EffectSet& set, double noise_floor_A) const;

  /// How alike the changes `a` and `b` make to `base`'s currents are over the held-out samples (their
  /// correlation).
  [[nodiscard]] double change_correlation(const EffectSet& base, const EffectSet& a, const EffectSet& b) const;

  [[nodiscard]] const ModelReplay& replay() const noexcept { return replay_; }
  [[nodiscard]] const EffectContext& context() const noexcept { return context_; }
  /// Samples the fits see (training blocks, replayed under the baseline).
  [[nodiscard]] std::size_t training_samples() const noexcept { return training_samples_; }

  /// The training residuals of a set, d and q interleaved, in sample order, each sample's scaled by the loss
  /// (tests and the outlier check; the fits stream).
  void training_residuals(const EffectSet& set, std::vector<double>& out) const;

 private:
  class FitCost;
  /// Per training block, in order: acc = init, then add(acc, residuals) for each fitted sample, with
  /// residuals[j] model j's (a miss of 1 kA per axis where a model predicts nothing finite), scaled by the loss.
  template <class Acc, class Add>
  std::vector<Acc> over_training(const std::vector<ExtendedModel>& models, const Acc& init, const Add& add) const;
  /// The same with each block's own start (`out`, one per training block, in order, added to and returned).
  template <class Acc, class Add>
  std::vector<Acc> over_training_from(const std::vector<ExtendedModel>& models, std::vector<Acc> out, const Add& add) const;

  const ModelReplay& replay_;
  EffectContext context_;
  std::vector<int> training_blocks_, heldout_blocks_;
  std::vector<bool> fitted_;  ///< per sample: in a training block and replayed under the baseline
  std::size_t training_samples_ = 0;
  std::uint64_t training_block_samples_ = 0;  ///< every sample of the training blocks (a pass's work per model)
  RobustLoss loss_;                           ///< least squares unless outliers remain (diagnosis.cpp)
};

}  // namespace rpem::analysis
