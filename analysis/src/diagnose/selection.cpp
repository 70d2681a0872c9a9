#include "rpem/analysis/diagnose/selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <optional>
#include <string>

namespace rpem::analysis {
namespace {

double gain_pct(const BlockScores& before, const BlockScores& after) {
  return 100.0 * (1.0 - std::sqrt(after.total() / std::max(before.total(), 1e-300)));
}

/// An effect whose parameters trade against a calibrated constant the model had identified — with it, the
/// constant's cluster-robust interval is wider than kIdentifiedHalfWidth — is told from that constant by
/// nothing in this log: what it lowers the residual by is the model's and the data's error the constant's
/// freedom already had (an L_d curve on averaged steady-state rows at nearly one d current). An effect
/// that shapes a constant (EffectRow::shapes_constant: a saturation curve times L_d) is identified only
/// with that constant, whether or not the baseline could calibrate it: fitted with it, the constant must be
/// admissible and identified. The reason, or nothing when the effect keeps every constant identified (the
/// constant a drift law is referred to excepted: the law takes that one's place by design).
std::optional<std::string> takes_a_constant(const EffectFitter& fitter, const EffectSet& before, const EffectSet& with,
                                            const CandidateScore& c, double noise_floor_A,
                                            const std::array<bool, kCalibrated.size()>& admissible) {
  std::optional<CalibrationIntervals> ci_before, ci_with;
  for (std::size_t k = 0; k < kCalibrated.size(); ++k) {
    const bool shaped = static_cast<int>(k) == c.effect.row->shapes_constant;
    if (!shaped && (!before.calibrated[k] || static_cast<int>(k) == c.effect.row->frees_constant)) continue;
    if (!ci_with) ci_with = fitter.intervals(with, noise_floor_A);
    if ((!shaped || admissible[k]) && identified(with, *ci_with, k)) continue;
    char text[480];
    if (shaped) {
      std::snprintf(text, sizeof text,
                    "%s lowers the held-out residual by %.1f %% (p = %.2g), but its curve multiplies %s, which this log "
                    "does not identify with it (95 %% interval ±%.0f %%%s): the curve's sensitivities are that "
                    "constant's, weighted by the logged currents, so the curve is not identifiable either; operation "
                    "over a wide range of that axis' current would identify both",
                    c.effect.label().c_str(), c.gain_pct, c.p_value, kCalibrated[k], 100.0 * ci_with->half_width[k],
                    admissible[k] ? "" : "; the excitation alone cannot pin it");
      return std::string(text);
    }
    if (!ci_before) ci_before = fitter.intervals(before, noise_floor_A);
    if (!identified(before, *ci_before, k)) continue;
    std::snprintf(text, sizeof text,
                  "%s lowers the held-out residual by %.1f %% (p = %.2g), but with it the calibrated %s is no longer "
                  "identified (95 %% interval ±%.0f %%, ±%.1f %% without it): the log cannot tell the effect from that "
                  "constant; operation that moves the effect's variable at fixed other conditions would separate them",
                  c.effect.label().c_str(), c.gain_pct, c.p_value, kCalibrated[k], 100.0 * ci_with->half_width[k],
                  100.0 * ci_before->half_width[k]);
    return std::string(text);
  }
  return std::nullopt;
}

/// The backward step: an effect named earlier that, with the effects found since, no longer passes the
/// acceptance tests against the model without it (refitted) had stood in for one of them — a cross-
/// coupling taking the voltage rotation of a command delay the round before the delay's fit found it —
/// and is withdrawn (reported, never named, and not a candidate again). The least useful goes first, one
/// at a time, each time against the model refitted without the ones withdrawn before.
void withdraw_explained(const EffectFitter& fitter, const SelectionOptions& options, double min_change2, Selection& sel,
                        BlockScores& current, std::vector<Effect>& excluded) {
  const EffectContext& context = fitter.context();
  while (sel.found.size() >= 2) {
    std::size_t weakest = sel.found.size();
    double weakest_gain = 0.0;
    EffectSet weakest_model;
    BlockScores weakest_scores;
    // The last one found has just passed these tests against the model without it.
    for (std::size_t j = 0; j + 1 < sel.found.size(); ++j) {
      const EffectSet without = fitter.fit(sel.model.without(sel.found[j].effect));
      const BlockScores scores = fitter.heldout(without);
      const double gain = gain_pct(scores, current);
      const double p = signed_rank_p(block_log_ratios(scores, current));
      const double change2 = rms(scores) * rms(scores) - rms(current) * rms(current);
      if (gain >= options.min_gain_pct && p <= options.max_p && change2 >= min_change2) continue;
      if (weakest == sel.found.size() || gain < weakest_gain) {
        weakest = j;
        weakest_gain = gain;
        weakest_model = without;
        weakest_scores = scores;
      }
    }
    if (weakest == sel.found.size()) return;
    const FoundEffect& f = sel.found[weakest];
    const ExtendedModel m = sel.model.model(context);
    std::string later;
    for (std::size_t j = weakest + 1; j < sel.found.size(); ++j)
      later += (later.empty() ? "" : ", ") + sel.found[j].effect.label();
    char reason[320];
    std::snprintf(reason, sizeof reason,
                  "found first (held-out gain %.1f %%), but with %s found later it no longer lowers the held-out "
                  "residual significantly (%.1f %% against the model refitted without it)",
                  f.gain_pct, later.c_str(), weakest_gain);
    sel.withdrawn.push_back({f.effect,
                             f.effect.row->describe(f.effect, m, context),
                             f.gain_pct,
                             {reason, "what " + later + " explain; it had stood in for it"}});
    excluded.push_back(f.effect);
    sel.found.erase(sel.found.begin() + static_cast<std::ptrdiff_t>(weakest));
    sel.model = weakest_model;
    current = weakest_scores;
  }
}

/// Whether `set` leaves an admissible constant configured.
bool leaves_configured(const EffectSet& set, const std::array<bool, kCalibrated.size()>& admissible) {
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (admissible[i] && !set.calibrated[i]) return true;
  }
  return false;
}

/// `set` with the admissible constants it leaves configured freed and refitted from its values (a warm
/// start), keeping those the calibration's rule then keeps (identification()) (refitted without the others); `set` itself when it keeps
/// none (`kept` false).
EffectSet with_admissible_constants(const EffectFitter& fitter, double noise_floor_A,
                                    const std::array<bool, kCalibrated.size()>& admissible, const EffectSet& set,
                                    bool& kept) {
  kept = false;
  EffectSet trial = set;
  std::vector<std::size_t> freed;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (trial.calibrated[i] || !admissible[i]) continue;
    trial.calibrated[i] = true;
    freed.push_back(i);
  }
  if (freed.empty()) return set;
  trial = fitter.fit(trial);  // from `set`'s fitted values: a warm start
  const CalibrationIntervals ci = fitter.intervals(trial, noise_floor_A);
  const double misfit = misfit_norm_A(fitter.training_samples(), rms(fitter.heldout(trial)), noise_floor_A);
  bool all = true;
  for (std::size_t i : freed) {
    if (identification(trial, ci, i, misfit) != Identification::kNot) {
      kept = true;
      continue;
    }
    trial.calibrated[i] = false;
    trial.calibration[i] = 0.0;
    all = false;
  }
  if (!kept) return set;
  return all ? trial : fitter.fit(trial);
}

/// One round of the selection: its candidates (best screened first), their fits, and how they compare.
struct Round {
  std::vector<CandidateScore> candidates;
  std::vector<std::vector<double>> starts;  ///< per candidate: the screening's best start
  double ssr_now = 0.0;                     ///< training sum of squares of the model as it is [A²]
  std::string name;                         ///< "round N: " (progress)
  std::size_t shortlisted = 0, leaders = 0;
  std::vector<EffectSet> fitted;
  std::vector<BlockScores> scores;
  std::vector<double> reduction;    ///< training sum of squares each fit removed [A²]
  BlockScores reference;            ///< what the candidates are judged against
  std::vector<std::size_t> ranked;  ///< the fitted ones, best held-out score first
  double before = 0.0;              ///< held-out RMS of the reference [A]
  double min_change2 = 0.0;
  const EffectContext* context = nullptr;
  const SelectionOptions* options = nullptr;

  /// Ranks the fitted candidates against `reference`.
  void rank() {
    ranked.clear();
    for (std::size_t i = 0; i < shortlisted; ++i) {
      CandidateScore& c = candidates[i];
      if (!c.fitted) continue;
      c.gain_pct = gain_pct(reference, scores[i]);
      c.block_log_ratio = block_log_ratios(reference, scores[i]);
      c.p_value = signed_rank_p(c.block_log_ratio);
      c.start = starts[i];
      c.parameters = fitted[i].parameters.back();
      ranked.push_back(i);
    }
    std::sort(ranked.begin(), ranked.end(),
              [&](std::size_t a, std::size_t b) { return scores[a].total() < scores[b].total(); });
  }
  /// Judged against the model as it is.
  void judge_against(const BlockScores& current, const EffectContext& c, const SelectionOptions& o, double change2) {
    reference = current;
    context = &c;
    options = &o;
    min_change2 = change2;
    rank();
    before = rms(reference);
  }
  /// Candidate i passes the acceptance tests: large, consistent, out of the noise, not negligible.
  [[nodiscard]] bool passes(std::size_t i) const {
    const CandidateScore& c = candidates[i];
    const double after = rms(scores[i]);
    if (c.gain_pct < options->min_gain_pct || c.p_value > options->max_p || before * before - after * after < min_change2)
      return false;
    return !(c.effect.row->negligible && c.effect.row->negligible(c.effect, fitted[i].model(*context), *context));
  }
  /// The second look's condition (second_look): none passes, but the best lowers the held-out residual by
  /// min_gain_pct, and the model leaves an admissible constant configured.
  [[nodiscard]] bool needs_second_look(const SelectionOptions& o, const EffectSet& model,
                                       const std::array<bool, kCalibrated.size()>& admissible) const {
    return std::none_of(ranked.begin(), ranked.end(), [&](std::size_t i) { return passes(i); }) && !ranked.empty() &&
           candidates[ranked.front()].gain_pct >= o.min_gain_pct && leaves_configured(model, admissible);
  }
};

/// The round's candidates — the catalogue's, less those in the model or excluded — screened against the model
/// and ordered by the training gain the screening credits them with, best first (none: nothing to screen).
std::optional<Round> screen_round(const EffectFitter& fitter, const Selection& sel, const std::vector<Effect>& excluded) {
  Round round;
  std::vector<Effect> effects;
  for (const Effect& e : candidates(fitter.context())) {
    if (sel.model.contains(e) || std::find(excluded.begin(), excluded.end(), e) != excluded.end()) continue;
    effects.push_back(e);
  }
  if (effects.empty()) return std::nullopt;
  round.name = "round " + std::to_string(sel.rounds.size() + 1) + ": ";
  if (Monitor* m = fitter.replay().monitor())
    m->stage(round.name + "screening " + std::to_string(effects.size()) + " candidates", 0);
  Screening screening = fitter.screen(sel.model, effects);
  round.ssr_now = screening.ssr;
  std::vector<std::size_t> order(effects.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return screening.gain[a] > screening.gain[b]; });
  for (std::size_t i : order) {
    CandidateScore c;
    c.effect = effects[i];
    c.screen_ssr = screening.gain[i];
    round.candidates.push_back(c);
    round.starts.push_back(std::move(screening.starts[i]));
  }
  return round;
}

/// Fits the shortlist: the best few, without those the screening credits with less than a small share of
/// the best (they cannot win unless the screening's first step misleads by that much); the leaders first, a
/// later one only if its screening could rival what the leaders' fits achieved.
void fit_shortlist(const EffectFitter& fitter, const SelectionOptions& options, const EffectSet& model, Round& round) {
  std::vector<CandidateScore>& c = round.candidates;
  std::size_t shortlisted = std::min<std::size_t>(c.size(), static_cast<std::size_t>(options.shortlist));
  while (shortlisted > 2 && c[shortlisted - 1].screen_ssr < options.shortlist_share * c.front().screen_ssr) --shortlisted;
  if (Monitor* m = fitter.replay().monitor())
    m->stage(round.name + "fitting the " + std::to_string(shortlisted) + " best", 0);
  round.shortlisted = shortlisted;
  round.fitted.assign(shortlisted, EffectSet{});
  round.scores.assign(shortlisted, BlockScores{});
  round.reduction.assign(shortlisted, 0.0);
  auto fit = [&](std::size_t i) {
    double ssr = 0.0;
    round.fitted[i] = fitter.fit(model.with(c[i].effect, fitter.context(), round.starts[i]), &ssr);
    round.reduction[i] = round.ssr_now - ssr;
    round.scores[i] = fitter.heldout(round.fitted[i]);
    c[i].fitted = true;
  };
  const WorkPool& pool = fitter.replay().pool();
  round.leaders = std::min<std::size_t>(shortlisted, static_cast<std::size_t>(std::max(options.leaders, 1)));
  pool.parallel_for(round.leaders, fit);
  const double achieved =
      *std::max_element(round.reduction.begin(), round.reduction.begin() + static_cast<std::ptrdiff_t>(round.leaders));
  std::vector<std::size_t> rivals;
  for (std::size_t i = round.leaders; i < shortlisted; ++i) {
    if (c[i].screen_ssr >= options.rival_share * achieved) rivals.push_back(i);
  }
  pool.parallel_for(rivals.size(), [&](std::size_t j) { fit(rivals[j]); });
}

/// The second look (docs/diagnose.md, "Constants a missing effect hid"): a constant the excitation pins but
/// the calibration left configured — its cluster-robust interval widened by the residual of an effect still
/// missing — held at a wrong value while a candidate is fitted, biases the candidate and makes the blocks
/// disagree. When no candidate passes but one lowers the held-out residual by min_gain_pct, the leaders are
/// fitted again with those constants free (kept only if then identified), from their fits; the reference is
/// the better of the model as it is and the model with the same constants free, so that what the
/// constants' freedom alone brings is not credited to an effect.
void second_look(const EffectFitter& fitter, double noise_floor_A, const std::array<bool, kCalibrated.size()>& admissible,
                 const EffectSet& model, Round& round) {
  std::vector<std::size_t> again;
  for (std::size_t i : round.ranked) {
    if (again.size() < round.leaders && round.candidates[i].gain_pct >= round.options->min_gain_pct) again.push_back(i);
  }
  EffectSet freed_model = model;
  bool freed_kept = false;
  fitter.replay().pool().parallel_for(again.size() + 1, [&](std::size_t j) {
    bool kept = false;
    if (j == again.size()) {
      freed_model = with_admissible_constants(fitter, noise_floor_A, admissible, model, kept);
      freed_kept = kept;
      return;
    }
    const std::size_t i = again[j];
    round.fitted[i] = with_admissible_constants(fitter, noise_floor_A, admissible, round.fitted[i], kept);
    if (kept) round.scores[i] = fitter.heldout(round.fitted[i]);
  });
  if (freed_kept) {
    const BlockScores freed_scores = fitter.heldout(freed_model);
    if (freed_scores.total() < round.reference.total()) round.reference = freed_scores;
  }
  round.rank();
  round.before = rms(round.reference);
}

/// The best candidate that passes and is plausible; those that pass but are implausible, or take a constant
/// the model had identified, are reported, excluded and set aside (`set_aside`). None: no candidate passed.
std::optional<std::size_t> best_plausible(const EffectFitter& fitter, double noise_floor_A,
                                          const std::array<bool, kCalibrated.size()>& admissible, const Round& round,
                                          Selection& sel, std::vector<Effect>& excluded, bool& set_aside) {
  const EffectContext& context = fitter.context();
  for (std::size_t i : round.ranked) {
    const CandidateScore& c = round.candidates[i];
    if (!round.passes(i)) continue;  // the best that passes: each is tested on its own
    const ExtendedModel m = round.fitted[i].model(context);
    std::optional<Implausibility> why;
    if (c.effect.row->judge && c.effect.row->judge(c.effect, m, context, {})) {
      // Judged again within the fitted parameter's own uncertainty.
      const CalibrationIntervals ci = fitter.intervals(round.fitted[i], noise_floor_A);
      why = c.effect.row->judge(c.effect, m, context, ci.effect_half_width.back());
    }
    if (!why) {
      if (const std::optional<std::string> lost =
              takes_a_constant(fitter, sel.model, round.fitted[i], c, noise_floor_A, admissible)) {
        sel.not_identifiable.push_back({{c.effect.label()}, *lost});
        excluded.push_back(c.effect);
        set_aside = true;
        continue;
      }
      return i;
    }
    sel.implausible.push_back({c.effect, c.effect.row->describe(c.effect, m, context), c.gain_pct, *why});
    excluded.push_back(c.effect);
    set_aside = true;
  }
  return std::nullopt;
}

/// The winner and the rivals that pass too, that the held-out blocks do not tell from it, and that change the
/// model in the same way (the rivals are excluded): a group of more than one makes the winner a guess, and
/// nobody is named.
Unidentifiable ambiguous_group(const EffectFitter& fitter, const SelectionOptions& options, const EffectSet& model,
                               const Round& round, std::size_t best, std::vector<Effect>& excluded) {
  const CandidateScore& winner = round.candidates[best];
  Unidentifiable group{{winner.effect.label()}, ""};
  for (std::size_t i : round.ranked) {
    const CandidateScore& rival = round.candidates[i];
    if (i == best || rival.effect.name() == winner.effect.name()) continue;
    if (!round.passes(i)) continue;
    if (std::find(excluded.begin(), excluded.end(), rival.effect) != excluded.end()) continue;
    const double p_preferred = signed_rank_p(block_log_ratios(round.scores[i], round.scores[best]));
    if (p_preferred <= options.ambiguity_p) continue;
    const double corr = fitter.change_correlation(model, round.fitted[best], round.fitted[i]);
    if (std::abs(corr) < options.ambiguity_correlation) continue;
    char text[640];
    std::snprintf(text, sizeof text,
                  "%s%s and %s change the model's currents the same way in this log (correlation %.3f) and lower "
                  "the held-out residual alike (%.1f %% and %.1f %%; the held-out blocks prefer neither, p = %.2f); a "
                  "log with %s would separate them",
                  group.reason.empty() ? "" : "; ", winner.effect.label().c_str(), rival.effect.label().c_str(), corr,
                  winner.gain_pct, rival.gain_pct, p_preferred, separating_data(winner.effect, rival.effect).c_str());
    group.reason += text;
    group.effects.push_back(rival.effect.label());
    excluded.push_back(rival.effect);
  }
  return group;
}

}  // namespace

double rms(const BlockScores& b) { return b.samples ? std::sqrt(b.total() / static_cast<double>(b.samples)) : 0.0; }

std::vector<double> block_log_ratios(const BlockScores& before, const BlockScores& after) {
  std::vector<double> r;
  for (std::size_t b = 0; b < std::min(before.ssr.size(), after.ssr.size()); ++b) {
    r.push_back(std::log(std::max(before.ssr[b], 1e-300) / std::max(after.ssr[b], 1e-300)));
  }
  return r;
}

double signed_rank_p(const std::vector<double>& values) {
  // Blocks the effect leaves unchanged (|ln ratio| below round-off) carry no evidence either way.
  std::vector<double> d;
  for (double v : values) {
    if (std::abs(v) > 1e-9) d.push_back(v);
  }
  const std::size_t n = d.size();
  if (n == 0) return 1.0;
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return std::abs(d[a]) < std::abs(d[b]); });
  std::size_t w_plus = 0;  // sum of the ranks (1 … n) of the positive values
  for (std::size_t r = 0; r < n; ++r) {
    if (d[order[r]] > 0.0) w_plus += r + 1;
  }
  // Exact null distribution: the number of subsets of {1 … n} with each rank sum.
  const std::size_t max_sum = n * (n + 1) / 2;
  std::vector<double> ways(max_sum + 1, 0.0);
  ways[0] = 1.0;
  for (std::size_t r = 1; r <= n; ++r) {
    for (std::size_t w = max_sum; w >= r; --w) ways[w] += ways[w - r];
  }
  double tail = 0.0;
  for (std::size_t w = w_plus; w <= max_sum; ++w) tail += ways[w];
  return tail / std::pow(2.0, static_cast<double>(n));
}

bool readmit_constants(const EffectFitter& fitter, double noise_floor_A,
                       const std::array<bool, kCalibrated.size()>& admissible, EffectSet& model, BlockScores& scores) {
  bool kept = false;
  const EffectSet trial = with_admissible_constants(fitter, noise_floor_A, admissible, model, kept);
  if (!kept) return false;
  const BlockScores trial_scores = fitter.heldout(trial);
  if (rms(trial_scores) > rms(scores)) return false;
  model = trial;
  scores = trial_scores;
  return true;
}

Selection select_effects(const EffectFitter& fitter, const SelectionOptions& options, const EffectSet& start,
                         double noise_floor_A, const std::array<bool, kCalibrated.size()>& admissible) {
  Selection sel;
  sel.model = start;
  BlockScores current = fitter.heldout(sel.model);
  sel.start_heldout_rms_A = rms(current);
  // Accepted only if large, consistent, and standing out of the noise: the model change it brings (the
  // held-out RMS² it removes) must be at least (min_change_of_floor × the noise floor)².
  const double min_change2 = std::pow(options.min_change_of_floor * noise_floor_A, 2);
  std::vector<Effect> excluded, stand_ins;

  while (static_cast<int>(sel.found.size() + stand_ins.size()) < options.max_effects) {
    std::optional<Round> screened = screen_round(fitter, sel, excluded);
    if (!screened) break;
    Round& round = *screened;
    fit_shortlist(fitter, options, sel.model, round);
    round.judge_against(current, fitter.context(), options, min_change2);
    if (round.needs_second_look(options, sel.model, admissible))
      second_look(fitter, noise_floor_A, admissible, sel.model, round);
    sel.rounds.push_back(round.candidates);
    bool set_aside = false;
    const std::optional<std::size_t> best =
        best_plausible(fitter, noise_floor_A, admissible, round, sel, excluded, set_aside);
    if (!best) {
      if (set_aside) continue;  // only implausible ones passed: the next round looks again without them
      break;
    }
    const CandidateScore winner = round.candidates[*best];
    if (Unidentifiable group = ambiguous_group(fitter, options, sel.model, round, *best, excluded);
        group.effects.size() > 1) {
      // The winner stays in the model as an unnamed stand-in, so that no later candidate is named for the
      // residual the group explains; it is taken out again at the end.
      sel.not_identifiable.push_back(std::move(group));
      stand_ins.push_back(winner.effect);
      sel.model = round.fitted[*best];
      current = round.scores[*best];
      continue;
    }
    sel.found.push_back({winner.effect, rms(round.reference), rms(round.scores[*best]), winner.gain_pct, winner.p_value});
    sel.model = round.fitted[*best];
    current = round.scores[*best];
    withdraw_explained(fitter, options, min_change2, sel, current, excluded);
    readmit_constants(fitter, noise_floor_A, admissible, sel.model, current);
  }
  if (!stand_ins.empty()) {
    EffectSet named = sel.model;
    for (const Effect& e : stand_ins) named = named.without(e);
    sel.model = named.effects.empty() ? start : fitter.fit(named);
    current = fitter.heldout(sel.model);
  }
  readmit_constants(fitter, noise_floor_A, admissible, sel.model, current);
  sel.extended_heldout_rms_A = rms(current);
  for (const Unidentifiable& u : unobservable(fitter.context())) sel.not_identifiable.push_back(u);
  return sel;
}

}  // namespace rpem::analysis
