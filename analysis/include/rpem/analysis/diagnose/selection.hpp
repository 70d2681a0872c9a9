#pragma once
// Forward selection of effects (docs/diagnose.md, "How an effect is accepted"), starting from the
// calibrated baseline. Each round screens every remaining candidate, fits the most promising jointly
// with the effects already found and the calibrated constants, and accepts the one that lowers the
// held-out residual most — if it is physically plausible (a drift law's coefficient in a material's
// range; an implausible one is reported, never named, and the next candidate takes its place) and only if the held-out gain is both large
// (≥ min_gain_pct of RMS) and consistent across the held-out blocks: a one-sided Wilcoxon signed-rank
// test on the per-block log ratios ln(SSR before/SSR after) (blocks the effect cannot touch have a
// ratio of 0 and drop out) must give p ≤ max_p. So noise, which a training fit always "explains" a
// little, is not named as an effect. Candidates that explain the same residual equally well and in the
// same way are reported together as not identifiable instead of one of them being guessed; the best of
// them stays in the model, unnamed, for the rest of the selection, so that no later candidate is named
// for that residual either, and is taken out of the final model. After each effect found, a backward step
// withdraws an effect named earlier that no longer passes the same tests against the model refitted
// without it (it had stood in for one found later).

#include <string>
#include <vector>

#include "rpem/analysis/diagnose/effect_fit.hpp"

namespace rpem::analysis {

struct SelectionOptions {
  double min_gain_pct = 2.0;  ///< held-out RMS gain an effect must bring
  double max_p = 0.01;        ///< signed-rank p over the held-out blocks
  /// The held-out RMS² an effect removes must be at least (this × the noise floor)²: a model change below
  /// 0.4 of the sensors' noise (RMS) is not worth naming, however consistent.
  double min_change_of_floor = 0.4;
  int max_effects = 4;
  int shortlist = 4;              ///< candidates fitted in full per round (at most) …
  double shortlist_share = 0.05;  ///< … of those screened at this share of the best or more (at least 2);
  /// after the first `leaders` fits, a shortlisted candidate is fitted only if its screening credits it
  /// with this share of the training gain the best of them achieved (it could not rival it otherwise).
  double rival_share = 0.25;
  /// Candidates fitted first in each round (whatever the threads: the results do not depend on them).
  int leaders = 2;
  /// Ambiguity: a rival that passes the same acceptance tests, that the held-out blocks do not prefer
  /// the winner to (signed-rank p above this) …
  double ambiguity_p = 0.05;
  /// … and whose change to the model's currents correlates at least this well with the winner's.
  double ambiguity_correlation = 0.9;
};

/// One candidate's result in one round (the report's audit trail).
struct CandidateScore {
  Effect effect;
  double screen_ssr = 0.0;  ///< predicted training gain [A²]
  bool fitted = false;
  double gain_pct = 0.0;                ///< held-out RMS gain over the round's starting model
  double p_value = 1.0;                 ///< signed-rank test of the held-out block improvements
  std::vector<double> start;            ///< the screening's best start (scaled, the catalogue's units)
  std::vector<double> parameters;       ///< fitted (scaled)
  std::vector<double> block_log_ratio;  ///< ln(SSR before / SSR after) per held-out block
};

struct FoundEffect {
  Effect effect;
  double heldout_rms_before_A = 0.0;  ///< the model before this effect was added
  double heldout_rms_after_A = 0.0;   ///< … and after (both with the effects found or stood in before it)
  double gain_pct = 0.0;
  double p_value = 1.0;
};

/// A candidate that would have been accepted but whose fitted value is not physical.
struct ImplausibleEffect {
  Effect effect;
  std::vector<NamedValue> parameters;
  double gain_pct = 0.0;
  Implausibility why;
};

struct Selection {
  EffectSet model;  ///< the calibrated constants and the found (named) effects, fitted jointly
  std::vector<FoundEffect> found;
  std::vector<Unidentifiable> not_identifiable;
  std::vector<ImplausibleEffect> implausible;
  /// Found, then negligible once the calibrated constants were refitted with the effects (diagnosis.cpp).
  std::vector<ImplausibleEffect> negligible;
  /// Found, then withdrawn: with the effects found after it, it no longer passed the acceptance tests
  /// against the model without it (the backward step after each effect found).
  std::vector<ImplausibleEffect> withdrawn;
  std::vector<std::vector<CandidateScore>> rounds;
  double start_heldout_rms_A = 0.0;  ///< the model selection started from (the calibrated baseline)
  double extended_heldout_rms_A = 0.0;
};

/// `start`: the calibrated baseline (its calibrated constants stay free in every fit); `noise_floor_A`:
/// the log's (verdict.hpp); `admissible`: the constants the log's excitation pins down (kCalibrated order)
/// — one the baseline could not calibrate (the model's errors widened its interval) is readmitted after
/// each effect found, where it is then identified and the held-out residual no worse.
[[nodiscard]] Selection select_effects(const EffectFitter& fitter, const SelectionOptions& options, const EffectSet& start,
                                       double noise_floor_A, const std::array<bool, kCalibrated.size()>& admissible);

/// Frees the admissible constants `model` does not calibrate, refits, and keeps those then identified if
/// the held-out residual (`scores`, updated) is no worse; whether any was kept.
bool readmit_constants(const EffectFitter& fitter, double noise_floor_A,
                       const std::array<bool, kCalibrated.size()>& admissible, EffectSet& model, BlockScores& scores);

/// Held-out RMS of block scores [A].
[[nodiscard]] double rms(const BlockScores& b);
/// Per-block log ratios ln(SSR before/SSR after).
[[nodiscard]] std::vector<double> block_log_ratios(const BlockScores& before, const BlockScores& after);
/// One-sided Wilcoxon signed-rank p-value that the values lie above zero (zeros dropped; exact).
[[nodiscard]] double signed_rank_p(const std::vector<double>& values);

}  // namespace rpem::analysis
