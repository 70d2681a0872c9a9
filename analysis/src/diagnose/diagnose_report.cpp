// report.md and report.html: a person's view of the diagnosis (docs/diagnose.md, "Reading the report").
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/analysis/report_document.hpp"

namespace rpem::analysis {
namespace {

/// v with `significant` significant digits.
std::string num(double v, int significant = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", significant, v);
  return buf;
}

/// v with `decimals` decimals.
std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string pct(double v) { return fixed(v, 1) + " %"; }

std::string optional_pct(const std::optional<double>& v) { return v ? pct(*v) : "—"; }

std::string parameters_text(const std::vector<NamedValue>& values) {
  std::string s;
  for (const NamedValue& v : values) {
    s += (s.empty() ? "" : ", ") + v.name + " = " + (v.text.empty() ? num(v.value) : v.text);
  }
  return s;
}

constexpr std::array<const char*, kCalibrated.size()> kCalibratedText{"ψm [Wb]", "R_s [Ω]", "L_d [H]", "L_q [H]"};

void summary(ReportDocument& doc, const Diagnosis& d, const std::string& config_path) {
  const Selection& s = d.selection;
  const LogData& log = *d.log;
  std::string text = "**Verdict: " + std::string(to_string(d.verdict.kind)) + "** — the final held-out residual is " +
                     num(s.extended_heldout_rms_A) + " A RMS, ";
  if (d.verdict.ratio) {
    text += num(*d.verdict.ratio, 3) + " times the noise floor of " + num(d.verdict.noise_floor_A.value_or(0.0), 3) +
            " A estimated from the data (explained up to " + num(kExplainedRatio, 2) + " times).";
  } else {
    text += "and whether that is noise cannot be told: the noise floor cannot be measured on this log (" +
            d.noise_floor.unknown_reason + ").";
  }
  doc.paragraph(text);
  text = "The configuration (`" + config_path +
         "`, its whole model: model extensions and drift laws) replayed on the inputs of `" + log.path + "` (" +
         (log.sessions() > 1 ? "its " + std::to_string(log.sessions()) + " logs joined as sessions, below; " : "") +
         std::to_string(log.size()) + " samples over " + num(log.t_end_s - log.t_start_s, 3) + " s, " +
         (log.mode == ModelMode::kTransient ? "transient: the open-loop discrete predictor"
                                            : "steady state: the closed-form steady-state model") +
         ") predicts the currents with a held-out residual of **" + num(d.baseline_heldout_rms_A) +
         " A RMS**; with the "
         "machine's constants calibrated on the log, **" +
         num(d.calibration.heldout_rms_A) + " A**. ";
  const std::vector<std::string> findings = calibration_findings(d);
  for (std::size_t i = 0; i < findings.size(); ++i)
    text += (i ? "; " : "Calibration: ") + findings[i] + (i + 1 == findings.size() ? ". " : "");
  if (s.found.empty()) {
    text += "No effect of the catalogue lowers the calibrated baseline's residual significantly.";
  } else {
    text += "Found: ";
    for (std::size_t j = 0; j < s.found.size(); ++j) {
      text += (j ? "; " : "") + std::string("**") + s.found[j].effect.label() + "** (" +
              parameters_text(found_parameters(d, j)) + ")";
    }
    text += ". The extended model lowers the held-out residual to **" + num(s.extended_heldout_rms_A) + " A** (" +
            pct(100.0 * (1.0 - s.extended_heldout_rms_A / std::max(s.start_heldout_rms_A, 1e-300))) +
            " below the calibrated baseline).";
  }
  doc.paragraph(text);
  if (!s.implausible.empty()) {
    std::vector<std::string> items;
    for (const ImplausibleEffect& i : s.implausible) {
      items.push_back("`" + i.effect.label() + "` (" + parameters_text(i.parameters) + ", held-out gain " + pct(i.gain_pct) +
                      ") is not named: " + i.why.reason + ". More likely: " + i.why.more_likely + ".");
    }
    doc.paragraph("Physically implausible, not named:");
    doc.bullets(items);
  }
  if (!s.withdrawn.empty()) {
    std::vector<std::string> items;
    for (const ImplausibleEffect& i : s.withdrawn) {
      items.push_back("`" + i.effect.label() + "` (" + parameters_text(i.parameters) + ") is not named: " + i.why.reason +
                      "; " + i.why.more_likely + ".");
    }
    doc.paragraph("Withdrawn by the backward step:");
    doc.bullets(items);
  }
  if (!s.not_identifiable.empty()) {
    std::vector<std::string> items;
    for (const Unidentifiable& u : s.not_identifiable) {
      std::string names;
      for (const std::string& e : u.effects) names += (names.empty() ? "" : " / ") + ("`" + e + "`");
      items.push_back(names + ": " + u.reason);
    }
    doc.paragraph("Not identifiable from this log:");
    doc.bullets(items);
  }
}

/// A folder's logs, joined as one machine's sessions (nothing for one log).
void sessions(ReportDocument& doc, const Diagnosis& d) {
  const LogData& log = *d.log;
  if (log.sessions() < 2) return;
  doc.heading(1, "Sessions");
  doc.paragraph(
      "The folder's " + std::to_string(log.sessions()) +
      " logs are one machine's sessions, diagnosed together: each is read as it would be alone, and they lie one "
      "after another on the time axis (t below and in the figures), " +
      num(core::to_seconds(LogData::kSessionGap_ns), 2) +
      " s apart. Every replay and the estimator start afresh at each session's first sample (the estimator from the "
      "configuration, as on its log alone); the training and held-out blocks are cut in the time the sessions "
      "sampled, so a block may hold the end of one session and the start of the next. A drift against time is no "
      "candidate here: each session starts at its own temperature (a drift against a logged temperature is).");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t j = 0; j < log.sessions(); ++j) {
    const std::size_t first = log.session_first[j], end = log.session_end(j);
    std::size_t used = 0;
    for (std::size_t k = first; k < end; ++k) used += log.used(k) ? 1 : 0;
    rows.push_back({"`" + log.session_logs[j] + "`", std::to_string(end - first), std::to_string(used),
                    num(log.t_s(first), 6), num(log.t_s(end - 1), 6)});
  }
  doc.table({"log", "samples", "in the fits", "t first [s]", "t last [s]"}, rows);
}

void regimes(ReportDocument& doc, const Diagnosis& d) {
  const LogRegimes& r = d.regimes;
  doc.heading(1, "Regimes: what the fits take and what they leave out");
  doc.paragraph(
      "Each sample's regime as the estimator decides it (`rpem estimate` and rpemd run the same classifier; "
      "docs/derivations.md §13): the samples with the bridge off, with the dq frame not the rotor's, in a "
      "transient the model does not represent, or not finite enter no fit (" +
      std::to_string(r.excluded_used) + " here, besides " +
      std::to_string(d.log->excluded_idle + d.log->excluded_transitional) +
      " rows the steady-state replay leaves out as idle or in transition). The estimator over the log "
      "resynchronised " +
      std::to_string(r.counts.resyncs) + " times and skipped " + std::to_string(r.counts.outliers) +
      " samples as outliers.");
  std::vector<std::vector<std::string>> rows;
  const double total = static_cast<double>(std::max<std::uint64_t>(r.counts.samples, 1));
  for (const core::RegimeInfo& info : core::kRegimes) {
    const std::uint64_t n = r.counts.regimes[info.regime];
    if (n == 0) continue;
    rows.push_back({info.name, std::to_string(n), pct(100.0 * static_cast<double>(n) / total),
                    info.excluded ? "no (excluded)" : "yes"});
  }
  doc.table({"regime", "samples", "share", "in the fits"}, rows);
  if (!r.explanations.empty()) {
    doc.paragraph("More than " + num(100.0 * io::kExplainedShare, 2) +
                  " % of the samples were left out by a rule; which, and "
                  "what changes it:");
    doc.bullets(r.explanations);
  }
  if (const std::string note = io::assumed_frame_note(r.counts); !note.empty()) doc.paragraph("Note: " + note + ".");
  doc.figure("regimes.png",
             "The log against time, coloured by regime: speed and current amplitude of each regime's samples.");
}

void calibration(ReportDocument& doc, const Diagnosis& d) {
  const Calibration& c = d.calibration;
  doc.heading(1, "The calibrated baseline");
  doc.paragraph(
      "Before any effect, the machine's constants that this log identifies are fitted on the training blocks, "
      "jointly with every effect found later; a constant is identifiable when the log's excitation and noise "
      "floor alone pin it within ±" +
      num(100.0 * kIdentifiableHalfWidth, 2) +
      " % (95 %). Intervals: cluster-"
      "robust over the training blocks, at the final model. The RPEM estimator's own estimates with the "
      "configuration (mean over the last quarter of the log) are the cross-check.");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    const double hw = c.intervals.half_width[i] * c.value[i];
    std::string rpem = "—";
    if (i == 0 && d.estimates.method == "rpem") rpem = num(d.estimates.nominal_summary.psi_m_Wb);
    if (i == 1 && d.estimates.method == "rpem") rpem = num(d.estimates.nominal_summary.r_s_Ohm);
    rows.push_back(
        {kCalibratedText[i], num(c.configured[i]), c.identifiable[i] ? num(c.value[i]) : "not identifiable",
         c.identifiable[i] && std::isfinite(hw) ? "[" + num(c.value[i] - hw) + ", " + num(c.value[i] + hw) + "]" : "—",
         c.identifiable[i] ? "±" + pct(100.0 * mismatch_half_width(d, i)) : "—",
         c.identifiable[i] ? pct(100.0 * (c.configured[i] / c.value[i] - 1.0)) : "—", rpem});
  }
  doc.table({"constant", "configured", "calibrated", "95 % interval", "mismatch allowance", "configuration off by",
             "RPEM estimate"},
            rows);
  doc.paragraph(
      "The mismatch allowance is the largest bias the misfit the final model still leaves above the noise floor "
      "could put into a constant (0 when the model explains the log down to the floor; the whole residual where "
      "the floor is unknown); a configured value within the interval widened by it is not stated as off.");
  const std::vector<std::string> despite = calibrated_despite_mismatch(d);
  if (!despite.empty()) {
    doc.paragraph("Calibrated despite a large mismatch (a constant is identified when its interval is within ±" +
                  num(100.0 * kIdentifiedHalfWidth, 2) + " %, or — wider — when it excludes the configured value):");
    doc.bullets(despite);
  }
  std::string temps;
  if (d.context.t_magnet.logged)
    temps += " ψm at the log's mean magnet temperature, " + num(d.context.t_magnet.mean_C, 3) + " °C.";
  if (d.context.t_winding.logged)
    temps += " R_s at the mean winding temperature, " + num(d.context.t_winding.mean_C, 3) + " °C.";
  if (!temps.empty())
    doc.paragraph("Under a drift law the constants are the law's values at the log's mean temperature:" + temps);
}

void loss(ReportDocument& doc, const Diagnosis& d) {
  const OutlierCheck& o = d.outliers;
  if (!o.test.outliers) return;  // nothing beyond the Gaussian level: least squares, nothing to say
  doc.heading(1, "Outliers and the loss");
  std::string text = std::to_string(o.test.beyond) + " of the " + std::to_string(o.test.samples) +
                     " training samples lie beyond b = " + num(o.test.threshold_A, 3) +
                     " A (the level a Gaussian residual of "
                     "that scale, σ̂ = " +
                     num(o.test.scale_A, 3) +
                     " A per axis from the median, exceeds once in that many; "
                     "p = " +
                     num(o.test.p_value, 2) + "). Refitted under Huber's loss at b, the largest parameter change is " +
                     num(o.largest_shift, 2) + " times its 95 % half-width" +
                     (o.parameter.empty() ? "" : " (" + o.parameter + ")");
  if (!d.least_squares) {
    text += ": the tail does not decide the fit, which stays least squares.";
    doc.paragraph(text);
    return;
  }
  text +=
      ": the tail decided the least-squares fit, so calibration and every effect fit were run again minimising "
      "Huber's loss (squares within b, linear beyond), b re-estimated from each run's residuals: " +
      num(o.loss.threshold_A, 3) + " A after " + std::to_string(o.robust_runs) + " run" + (o.robust_runs == 1 ? "" : "s") +
      ". The held-out residuals in this report are √(mean ρ). ";
  std::string ls;
  for (const std::string& e : d.least_squares->found) ls += (ls.empty() ? "" : ", ") + e;
  text += "Least squares had found " + (ls.empty() ? std::string("no effect") : ls) + " (held-out " +
          num(d.least_squares->extended_heldout_rms_A) + " A RMS)";
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (d.least_squares->identifiable[i]) text += std::string(", ") + kCalibrated[i] + " " + num(d.least_squares->value[i]);
  }
  doc.paragraph(text + ".");
}

void effects_table(ReportDocument& doc, const Diagnosis& d) {
  if (d.selection.found.empty()) return;
  doc.heading(1, "Effects found");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t j = 0; j < d.selection.found.size(); ++j) {
    const FoundEffect& f = d.selection.found[j];
    const EstimatorCheck* c = estimator_check(d, j);
    std::string kept = "yes";
    if (c && c->applicable) {
      kept = std::string(c->kept ? "yes" : "no") + ": the estimator's held-out ε is " + num(c->with_A) + " A with it, " +
             num(c->without_A) + " A without";
    } else if (c) {
      kept = "yes (a steady-state log: no recursive estimator to check)";
    }
    rows.push_back({f.effect.label(), parameters_text(found_parameters(d, j)), num(f.heldout_rms_before_A),
                    num(f.heldout_rms_after_A), pct(f.gain_pct), num(f.p_value, 2), kept});
  }
  doc.table({"effect", "parameters (SI; final joint fit)", "held-out RMS before [A]", "after [A]", "gain", "p",
             "in extended.yaml"},
            rows);
  doc.paragraph(
      "Before and after are the held-out residual RMS of the model without and with the effect, each with the "
      "effects found before it. An effect goes into `extended.yaml` only if the RPEM estimator with it (and the "
      "effects kept before it) predicts the held-out blocks at least as well as without it; `rpem estimate "
      "--config extended.yaml` and rpemd use that file as it is, and `rpem diagnose --config extended.yaml` "
      "replays it as the baseline of the next recording.");
}

void verdict_section(ReportDocument& doc, const Diagnosis& d, const std::vector<std::string>& figures) {
  const VerdictKind kind = d.verdict.kind;
  doc.heading(1, kind == VerdictKind::kExplained     ? "What is left: noise"
                 : kind == VerdictKind::kUnexplained ? "What is left: unexplained"
                                                     : "What is left: undetermined");
  if (kind == VerdictKind::kExplained) {
    doc.paragraph("The final model's held-out residual is within " + num(kExplainedRatio, 2) +
                  " times the noise floor: what "
                  "is left is the sensors' noise.");
    return;
  }
  doc.paragraph(
      kind == VerdictKind::kUnexplained
          ? "The final model's held-out residual stays " + num(d.verdict.ratio.value_or(0.0), 3) +
                " times above the noise floor. Where it lives, and what would explain it:"
          : "The noise floor cannot be measured on this log, so the residual cannot be judged against it "
            "(`noise_floor_A: null`, `verdict: undetermined`). Why, where the residual lives, and what would tell:");
  doc.bullets(d.verdict.findings);
  auto has = [&](const char* f) { return std::find(figures.begin(), figures.end(), f) != figures.end(); };
  if (has("residual_map.png"))
    doc.paragraph(
        "The operating-point map (`residual_map.png`) and the content against the electrical "
        "angle (`harmonics.png`) below show it in full.");
}

void residuals(ReportDocument& doc, const Diagnosis& d, const std::vector<std::string>& figures) {
  const ResidualStatistics& st = d.statistics;
  auto has = [&](const char* f) { return std::find(figures.begin(), figures.end(), f) != figures.end(); };
  doc.heading(1, "What the configuration gets wrong");
  doc.paragraph("Residual RMS over all used samples: " + num(st.rms_A.before) + " A with the configuration, " +
                num(st.rms_A.after) + " A extended; at standstill " + num(st.standstill_rms_A.before) + " → " +
                num(st.standstill_rms_A.after) + " A, in motion " + num(st.motion_rms_A.before) + " → " +
                num(st.motion_rms_A.after) + " A.");
  doc.figure("residual_time.png",
             "Operating profile, residual RMS of the configuration (red) and the extended model "
             "(green), and the configuration's mean residual, against time.");
  doc.figure("residual_map.png", "Residual RMS over the speed × i_q plane: where the configuration errs, and what is left.");
  std::vector<std::vector<std::string>> rows;
  for (const RegionStatistics& r : st.regions) {
    rows.push_back({r.speed, r.load, std::to_string(r.samples), num(r.rms_A.before), num(r.rms_A.after),
                    num(r.mean_d_A.before), num(r.mean_q_A.before), num(r.mean_d_A.after), num(r.mean_q_A.after)});
  }
  doc.table({"speed", "load", "samples", "RMS configuration [A]", "RMS extended [A]", "mean ε_d configuration",
             "mean ε_q configuration", "mean ε_d extended", "mean ε_q extended"},
            rows);
  if (has("harmonics.png")) {
    doc.figure("harmonics.png",
               "Residual amplitude at harmonics of the electrical angle, in the dq frame: a current "
               "sensor offset shows at the 1st, a gain error at the 2nd, dead time at the 6th.");
    std::vector<std::vector<std::string>> h;
    for (const HarmonicContent& c : st.harmonics) {
      h.push_back({std::to_string(c.order), num(c.amplitude_A.before), num(c.amplitude_A.after)});
    }
    doc.table({"harmonic", "configuration [A]", "extended [A]"}, h);
  }
  if (has("phase_sign.png")) {
    doc.figure("phase_sign.png",
               "Mean residual of each phase while its current is positive and negative: dead time pulls "
               "the logged current below the model's in the current's direction.");
  }
  if (has("residual_temperature.png")) {
    doc.figure("residual_temperature.png", "The residual against the logged temperature: a thermal drift shows as a trend.");
  }
  std::vector<std::vector<std::string>> c;
  for (const RegressorCorrelation& r : st.correlations) {
    c.push_back({r.regressor, fixed(r.d.before, 3), fixed(r.q.before, 3), fixed(r.d.after, 3), fixed(r.q.after, 3)});
  }
  doc.paragraph("Correlation of the residual with candidate regressors:");
  doc.table({"regressor", "ε_d configuration", "ε_q configuration", "ε_d extended", "ε_q extended"}, c);
  doc.figure("overlay.png", d.log->mode == ModelMode::kTransient
                                ? "The logged current against both models in the 0.1 s where the configuration errs most."
                                : "The logged current against both models, row by row.");
}

void estimator(ReportDocument& doc, const Diagnosis& d) {
  const EstimatorComparison& c = d.estimates;
  if (c.nominal.empty()) return;
  doc.heading(1, "The estimator with the extended model");
  doc.paragraph(
      c.method == "rpem"
          ? "The RPEM estimator (as `rpem estimate` and rpemd run it) over this log with the input configuration "
            "and with `extended.yaml`. Values: mean over the last quarter of the log; errors: RMS against the "
            "truth over the second half, where a truth was given."
          : "A steady-state log cannot drive the recursive estimator (its samples lie seconds apart). Instead, "
            "each row's steady-state equations give the ψm and R_s the data implies — R_s = (u_d + ω·L_q·i_q)/i_d, "
            "ψm = (u_q − R_s·i_q)/ω − L_d·i_d, with the extended model's corrections — set against what the "
            "configuration assumes and what the extended model assumes (its drifts). A row implies a value only "
            "where the data's noise determines it (the value beyond z of its standard deviation; not ψm near "
            "standstill, not R_s where i_d is near zero). Values: mean over the last quarter; errors over the second "
            "half: RMS against the truth where one was given, else the median of the relative error's magnitude "
            "against the implied values (a few rows the steady-state model cannot represent imply anything at all; "
            "the figure's range leaves them out and says how many).");
  doc.figure("estimates.png", c.method == "rpem"
                                  ? "ψm and R_s estimated with the configuration (red) and the extended model (green)."
                                  : "ψm and R_s as the configuration (red) and the extended model (green) assume them, "
                                    "as the data implies them (black points) and, where given, the truth (dashed).");
  doc.table({"model", "ψm [Wb]", "R_s [Ω]", "ψm error", "R_s error"},
            {{"configuration", num(c.nominal_summary.psi_m_Wb), num(c.nominal_summary.r_s_Ohm),
              optional_pct(c.nominal_summary.psi_m_error_pct), optional_pct(c.nominal_summary.r_s_error_pct)},
             {"extended", num(c.extended_summary.psi_m_Wb), num(c.extended_summary.r_s_Ohm),
              optional_pct(c.extended_summary.psi_m_error_pct), optional_pct(c.extended_summary.r_s_error_pct)}});
}

void selection(ReportDocument& doc, const Diagnosis& d) {
  doc.heading(1, "How the effects were selected");
  doc.paragraph(
      "The log is cut into " + std::to_string(d.log->blocks) +
      " blocks of equal duration in the time it sampled (its pauses left out); even blocks train, odd blocks are "
      "held out. Each round ranks every remaining candidate by the training gain its first Gauss–Newton step predicts, fits the best " +
      std::to_string(d.options.selection.shortlist) +
      " jointly with the effects already found (Ceres), and accepts the one that lowers the held-out residual "
      "most — if it lowers its RMS by at least " +
      num(d.options.selection.min_gain_pct, 3) +
      " % and the held-out blocks agree (one-sided Wilcoxon signed-rank test on the per-block log ratios, p ≤ " +
      num(d.options.selection.max_p, 3) +
      "). Candidates the held-out blocks cannot tell from the winner, and that change the model alike, make "
      "it a guess: the group is reported as not identifiable and nobody is named for that residual.");
  for (std::size_t r = 0; r < d.selection.rounds.size(); ++r) {
    std::vector<std::vector<std::string>> rows;
    for (const CandidateScore& c : d.selection.rounds[r]) {
      if (!c.fitted) continue;
      rows.push_back({c.effect.label(), num(c.screen_ssr), pct(c.gain_pct), num(c.p_value, 2)});
    }
    doc.paragraph("Round " + std::to_string(r + 1) + ":");
    doc.table({"candidate", "screened training gain [A²]", "held-out gain", "p"}, rows);
  }
  const LogData& log = *d.log;
  if (log.excluded_idle + log.excluded_transitional > 0) {
    doc.paragraph("Left out of the steady-state analysis: " + std::to_string(log.excluded_idle) + " idle rows and " +
                  std::to_string(log.excluded_transitional) + " rows in transition between operating points.");
  }
  doc.paragraph("Diagnosis time: " + fixed(d.elapsed_s, 2) + " s.");
}

}  // namespace

void write_diagnose_report(const std::string& dir, const Diagnosis& d, const std::string& config_path) {
  const std::vector<std::string> figures = write_diagnose_figures(dir, d);
  ReportDocument doc("Diagnosis of " + d.log->path);
  summary(doc, d, config_path);
  sessions(doc, d);
  regimes(doc, d);
  calibration(doc, d);
  loss(doc, d);
  effects_table(doc, d);
  verdict_section(doc, d, figures);
  residuals(doc, d, figures);
  estimator(doc, d);
  selection(doc, d);
  for (const auto& [name, text] : {std::pair{"/report.md", doc.markdown()}, std::pair{"/report.html", doc.html()}}) {
    std::ofstream f(dir + name);
    if (!f || !(f << text)) throw std::runtime_error("cannot write " + dir + name);
  }
}

}  // namespace rpem::analysis
