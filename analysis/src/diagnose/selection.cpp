#include "rpem/analysis/diagnose/selection.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <optional>
#include <string>
#include <thread>
#include <tuple>

namespace rpem::analysis {
namespace {

/// Runs body(i) for i in [0, n) on `threads` threads.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& body) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) body(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min<int>(threads, static_cast<int>(n)); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

double gain_pct(const BlockScores& before, const BlockScores& after) {
  return 100.0 * (1.0 - std::sqrt(after.total() / std::max(before.total(), 1e-300)));
}

/// How alike two model changes are over the held-out samples.
double change_correlation(const EffectFitter& f, const EffectSet& base, const EffectSet& a, const EffectSet& b) {
  ReplayOutput r0, ra, rb;
  const ModelReplay& replay = f.replay();
  replay.run(base.model(f.context()), r0, Blocks::kHeldout);
  replay.run(a.model(f.context()), ra, Blocks::kHeldout);
  replay.run(b.model(f.context()), rb, Blocks::kHeldout);
  double ab = 0.0, aa = 0.0, bb = 0.0;
  const LogData& log = replay.log();
  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (!log.heldout(k) || !r0.valid[k] || !ra.valid[k] || !rb.valid[k]) continue;
    const core::Vec2 da = ra.model_A[k] - r0.model_A[k], db = rb.model_A[k] - r0.model_A[k];
    ab += da.dot(db);
    aa += da.squaredNorm();
    bb += db.squaredNorm();
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : 0.0;
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
    for (std::size_t j = weakest + 1; j < sel.found.size(); ++j) later += (later.empty() ? "" : ", ") + sel.found[j].effect.label();
    char reason[320];
    std::snprintf(reason, sizeof reason,
                  "found first (held-out gain %.1f %%), but with %s found later it no longer lowers the held-out "
                  "residual significantly (%.1f %% against the model refitted without it)",
                  f.gain_pct, later.c_str(), weakest_gain);
    sel.withdrawn.push_back({f.effect, f.effect.row->describe(f.effect, m, context), f.gain_pct,
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
                                    const std::array<bool, kCalibrated.size()>& admissible, const EffectSet& set, bool& kept) {
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

bool readmit_constants(const EffectFitter& fitter, double noise_floor_A, const std::array<bool, kCalibrated.size()>& admissible,
                       EffectSet& model, BlockScores& scores) {
  bool kept = false;
  const EffectSet trial = with_admissible_constants(fitter, noise_floor_A, admissible, model, kept);
  if (!kept) return false;
  const BlockScores trial_scores = fitter.heldout(trial);
  if (rms(trial_scores) > rms(scores)) return false;
  model = trial;
  scores = trial_scores;
  return true;
}

namespace {

/// One round of the forward selection: the candidates, screened and ordered best first, the shortlist's
/// fits and held-out scores, and their ranking against `reference`.
struct Round {
  std::vector<CandidateScore> candidates;
  std::vector<std::vector<double>> starts;  ///< each candidate's best start (EffectFitter::best_start)
  std::size_t shortlisted = 0;
  std::size_t leaders = 0;
  std::vector<EffectSet> fitted;
  std::vector<BlockScores> scores;
  /// The candidates are judged against this: the model as it is, or after a second look (second_look).
  BlockScores reference;
  std::vector<std::size_t> ranked;  ///< the fitted ones, best held-out score first

  void rank() {
    ranked.clear();
    for (std::size_t i = 0; i < shortlisted; ++i) {
      if (!candidates[i].fitted) continue;
      candidates[i].gain_pct = gain_pct(reference, scores[i]);
      candidates[i].block_log_ratio = block_log_ratios(reference, scores[i]);
      candidates[i].p_value = signed_rank_p(candidates[i].block_log_ratio);
      candidates[i].start = starts[i];
      candidates[i].parameters = fitted[i].parameters.back();
      ranked.push_back(i);
    }
    std::sort(ranked.begin(), ranked.end(), [&](std::size_t a, std::size_t b) { return scores[a].total() < scores[b].total(); });
  }
};

/// The effects not in the model and not excluded, unscored.
std::vector<CandidateScore> open_candidates(const EffectContext& context, const EffectSet& model,
                                            const std::vector<Effect>& excluded) {
  std::vector<CandidateScore> round;
  for (const Effect& e : candidates(context)) {
    if (model.contains(e) || std::find(excluded.begin(), excluded.end(), e) != excluded.end()) continue;
    CandidateScore candidate;
    candidate.effect = e;
    round.push_back(candidate);
  }
  return round;
}

/// Screens the round's candidates from their best starts and orders them by the screening, best first.
void screen(const EffectFitter& fitter, const SelectionOptions& options, const ScreenBasis& basis, const EffectSet& model,
            Round& r) {
  std::vector<CandidateScore>& round = r.candidates;
  std::vector<std::vector<double>> starts(round.size());
  parallel_for(round.size(), options.threads, [&](std::size_t i) {
    std::tie(starts[i], round[i].screen_ssr) = fitter.best_start(basis, model, round[i].effect);
  });
  std::vector<std::size_t> order(round.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return round[a].screen_ssr > round[b].screen_ssr; });
  std::vector<CandidateScore> sorted;
  std::vector<std::vector<double>> sorted_starts;
  for (std::size_t i : order) {
    sorted.push_back(round[i]);
    sorted_starts.push_back(starts[i]);
  }
  round = std::move(sorted);
  r.starts = std::move(sorted_starts);
}

/// Fits the shortlist: the best few of the screening, without those it credits with less than a small
/// share of the best (they cannot win unless the screening's first step misleads by that much); the
/// leaders first, a later one only if its screening could rival what the leaders' fits achieved.
void fit_shortlist(const EffectFitter& fitter, const SelectionOptions& options, const ScreenBasis& basis,
                   const EffectSet& model, Round& r) {
  std::vector<CandidateScore>& round = r.candidates;
  std::size_t shortlisted = std::min<std::size_t>(round.size(), static_cast<std::size_t>(options.shortlist));
  while (shortlisted > 2 && round[shortlisted - 1].screen_ssr < options.shortlist_share * round.front().screen_ssr) --shortlisted;
  r.shortlisted = shortlisted;
  r.fitted.assign(shortlisted, EffectSet{});
  r.scores.assign(shortlisted, BlockScores{});
  std::vector<double> reduction(shortlisted, 0.0);
  const double ssr_now = std::inner_product(basis.r0.begin(), basis.r0.end(), basis.r0.begin(), 0.0);
  const EffectContext& context = fitter.context();
  auto fit = [&](std::size_t i) {
    double ssr = 0.0;
    r.fitted[i] = fitter.fit(model.with(round[i].effect, context, r.starts[i]), &ssr);
    reduction[i] = ssr_now - ssr;
    r.scores[i] = fitter.heldout(r.fitted[i]);
    round[i].fitted = true;
  };
  r.leaders = std::min<std::size_t>(shortlisted, static_cast<std::size_t>(std::max(options.threads, 1)));
  parallel_for(r.leaders, options.threads, fit);
  const double achieved = *std::max_element(reduction.begin(), reduction.begin() + static_cast<std::ptrdiff_t>(r.leaders));
  std::vector<std::size_t> rivals;
  for (std::size_t i = r.leaders; i < shortlisted; ++i) {
    if (round[i].screen_ssr >= options.rival_share * achieved) rivals.push_back(i);
  }
  parallel_for(rivals.size(), options.threads, [&](std::size_t j) { fit(rivals[j]); });
}

/// Accepted only if large, consistent, and standing out of the noise: the model change a candidate brings
/// (the held-out RMS² it removes against the round's reference) must be at least
/// (min_change_of_floor × the noise floor)²; and not negligible by its row's own measure.
bool passes(const Round& r, std::size_t i, const SelectionOptions& options, double min_change2,
            const EffectContext& context) {
  const CandidateScore& c = r.candidates[i];
  const double before = rms(r.reference);
  const double after = rms(r.scores[i]);
  if (c.gain_pct < options.min_gain_pct || c.p_value > options.max_p || before * before - after * after < min_change2) return false;
  return !(c.effect.row->negligible && c.effect.row->negligible(c.effect, r.fitted[i].model(context), context));
}

/// The second look (docs/diagnose.md, "Constants a missing effect hid"): a constant the excitation pins but
/// the calibration left configured — its cluster-robust interval widened by the residual of an effect still
/// missing — held at a wrong value while a candidate is fitted, biases the candidate and makes the blocks
/// disagree. When no candidate passes but one lowers the held-out residual by min_gain_pct, the leaders are
/// fitted again with those constants free (kept only if then identified), from their fits; the reference
/// is the better of the model as it is and the model with the same constants free, so that what the
/// constants' freedom alone brings is not credited to an effect.
void second_look(const EffectFitter& fitter, const SelectionOptions& options, double noise_floor_A,
                 const std::array<bool, kCalibrated.size()>& admissible, const EffectSet& model, Round& r) {
  std::vector<std::size_t> again;
  for (std::size_t i : r.ranked) {
    if (again.size() < r.leaders && r.candidates[i].gain_pct >= options.min_gain_pct) again.push_back(i);
  }
  EffectSet freed_model = model;
  bool freed_kept = false;
  parallel_for(again.size() + 1, options.threads, [&](std::size_t j) {
    bool kept = false;
    if (j == again.size()) {
      freed_model = with_admissible_constants(fitter, noise_floor_A, admissible, model, kept);
      freed_kept = kept;
      return;
    }
    const std::size_t i = again[j];
    r.fitted[i] = with_admissible_constants(fitter, noise_floor_A, admissible, r.fitted[i], kept);
    if (kept) r.scores[i] = fitter.heldout(r.fitted[i]);
  });
  if (freed_kept) {
    const BlockScores freed_scores = fitter.heldout(freed_model);
    if (freed_scores.total() < r.reference.total()) r.reference = freed_scores;
  }
  r.rank();
}

/// The best ranked candidate that passes and is plausible and identifiable (each tested on its own);
/// implausible ones and those that take a constant's place are reported, excluded, and `set_aside` set.
/// r.shortlisted when none.
std::size_t best_plausible(const EffectFitter& fitter, const SelectionOptions& options, double noise_floor_A,
                           const std::array<bool, kCalibrated.size()>& admissible, double min_change2, const Round& r,
                           Selection& sel, std::vector<Effect>& excluded, bool& set_aside) {
  const EffectContext& context = fitter.context();
  for (std::size_t i : r.ranked) {
    const CandidateScore& c = r.candidates[i];
    if (!passes(r, i, options, min_change2, context)) continue;
    const ExtendedModel m = r.fitted[i].model(context);
    std::optional<Implausibility> why;
    if (c.effect.row->judge && c.effect.row->judge(c.effect, m, context, {})) {
      // Judged again within the fitted parameter's own uncertainty.
      const CalibrationIntervals ci = fitter.intervals(r.fitted[i], noise_floor_A);
      why = c.effect.row->judge(c.effect, m, context, ci.effect_half_width.back());
    }
    if (!why) {
      if (const std::optional<std::string> lost = takes_a_constant(fitter, sel.model, r.fitted[i], c, noise_floor_A, admissible)) {
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
  return r.shortlisted;
}

/// Rivals that pass too, that the held-out blocks do not tell from the winner, and that change the model in
/// the same way, make the winner a guess: the group (the winner first) and why; the rivals are excluded.
std::vector<std::string> ambiguous_group(const EffectFitter& fitter, const SelectionOptions& options, double min_change2,
                                         const Round& r, std::size_t best, const EffectSet& model,
                                         std::vector<Effect>& excluded, std::string& reason) {
  const CandidateScore& winner = r.candidates[best];
  std::vector<std::string> group = {winner.effect.label()};
  for (std::size_t i : r.ranked) {
    const CandidateScore& rival = r.candidates[i];
    if (i == best || rival.effect.name() == winner.effect.name()) continue;
    if (!passes(r, i, options, min_change2, fitter.context())) continue;
    if (std::find(excluded.begin(), excluded.end(), rival.effect) != excluded.end()) continue;
    const double p_preferred = signed_rank_p(block_log_ratios(r.scores[i], r.scores[best]));
    if (p_preferred <= options.ambiguity_p) continue;
    const double corr = change_correlation(fitter, model, r.fitted[best], r.fitted[i]);
    if (std::abs(corr) < options.ambiguity_correlation) continue;
    char text[640];
    std::snprintf(text, sizeof text,
                  "%s%s and %s change the model's currents the same way in this log (correlation %.3f) and lower "
                  "the held-out residual alike (%.1f %% and %.1f %%; the held-out blocks prefer neither, p = %.2f); a "
                  "log with %s would separate them",
                  reason.empty() ? "" : "; ", winner.effect.label().c_str(), rival.effect.label().c_str(), corr,
                  winner.gain_pct, rival.gain_pct, p_preferred, separating_data(winner.effect, rival.effect).c_str());
    reason += text;
    group.push_back(rival.effect.label());
    excluded.push_back(rival.effect);
  }
  return group;
}

}  // namespace

Selection select_effects(const EffectFitter& fitter, const SelectionOptions& options, const EffectSet& start,
                         double noise_floor_A, const std::array<bool, kCalibrated.size()>& admissible) {
  Selection sel;
  sel.model = start;
  const EffectContext& context = fitter.context();
  BlockScores current = fitter.heldout(sel.model);
  sel.start_heldout_rms_A = rms(current);
  std::vector<Effect> excluded, stand_ins;
  const double min_change2 = std::pow(options.min_change_of_floor * noise_floor_A, 2);

  while (static_cast<int>(sel.found.size() + stand_ins.size()) < options.max_effects) {
    Round r;
    r.candidates = open_candidates(context, sel.model, excluded);
    if (r.candidates.empty()) break;
    const ScreenBasis basis = fitter.screen_basis(sel.model);
    screen(fitter, options, basis, sel.model, r);
    fit_shortlist(fitter, options, basis, sel.model, r);
    r.reference = current;
    r.rank();
    const auto pass = [&](std::size_t i) { return passes(r, i, options, min_change2, context); };
    if (std::none_of(r.ranked.begin(), r.ranked.end(), pass) && !r.ranked.empty() &&
        r.candidates[r.ranked.front()].gain_pct >= options.min_gain_pct && leaves_configured(sel.model, admissible)) {
      second_look(fitter, options, noise_floor_A, admissible, sel.model, r);
    }
    sel.rounds.push_back(r.candidates);
    bool set_aside = false;
    const std::size_t best =
        best_plausible(fitter, options, noise_floor_A, admissible, min_change2, r, sel, excluded, set_aside);
    if (best == r.shortlisted) {
      if (set_aside) continue;  // only implausible ones passed: the next round looks again without them
      break;
    }
    const CandidateScore winner = r.candidates[best];
    std::string reason;
    std::vector<std::string> group = ambiguous_group(fitter, options, min_change2, r, best, sel.model, excluded, reason);
    if (group.size() > 1) {
      // The winner stays in the model as an unnamed stand-in, so that no later candidate is named for the
      // residual the group explains; it is taken out again at the end.
      sel.not_identifiable.push_back({group, reason});
      stand_ins.push_back(winner.effect);
      sel.model = r.fitted[best];
      current = r.scores[best];
      continue;
    }

    sel.found.push_back({winner.effect, rms(r.reference), rms(r.scores[best]), winner.gain_pct, winner.p_value});
    sel.model = r.fitted[best];
    current = r.scores[best];
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
  for (const Unidentifiable& u : unobservable(context)) sel.not_identifiable.push_back(u);
  return sel;
}

}  // namespace rpem::analysis
