// diagnosis.json and extended.yaml (schema: docs/diagnose.md).
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "rpem/analysis/diagnose/diagnose_output.hpp"

namespace rpem::analysis {
namespace {

/// The calibrated constants' names in a person's words.
constexpr std::array<const char*, kCalibrated.size()> kCalibratedName{"ψm", "R_s", "L_d", "L_q"};

nlohmann::json params_json(const std::vector<NamedValue>& values) {
  nlohmann::json p = nlohmann::json::object();
  for (const NamedValue& v : values) p[v.name] = v.text.empty() ? nlohmann::json(v.value) : nlohmann::json(v.text);
  return p;
}

nlohmann::json optional_json(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

nlohmann::json finite_json(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json summary_json(const EstimateSummary& s) {
  return {{"psi_m_Wb", s.psi_m_Wb},
          {"r_s_Ohm", s.r_s_Ohm},
          {"psi_m_error_pct", optional_json(s.psi_m_error_pct)},
          {"r_s_error_pct", optional_json(s.r_s_error_pct)}};
}

nlohmann::json drift_json(const io::ParameterDrift& d) {
  if (d.law)
    return {{"coeff_per_K", d.law->coeff_per_K}, {"reference_C", d.law->reference_C}, {"value_ref", d.law->value_ref}};
  if (d.rel_change) return {{"rel_change", *d.rel_change}};
  return nullptr;
}

nlohmann::json calibration_json(const Diagnosis& d) {
  const Calibration& c = d.calibration;
  nlohmann::json j;
  nlohmann::json configured = nlohmann::json::object(), identifiable = nlohmann::json::array();
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    const std::string key = kCalibrated[i];
    j[key] = c.value[i];
    const double hw = c.intervals.half_width[i] * c.value[i];
    j[key + "_ci95"] = c.identifiable[i] && std::isfinite(hw) ? nlohmann::json({c.value[i] - hw, c.value[i] + hw})
                                                              : nlohmann::json(nullptr);
    // Unknown without a noise floor (the excitation test then admits every excited constant).
    j[key + "_excitation_ci95_rel"] =
        d.noise_floor.value_A ? finite_json(c.intervals.excitation_half_width[i]) : nlohmann::json(nullptr);
    j[key + "_mismatch_rel"] = c.identifiable[i] ? nlohmann::json(mismatch_half_width(d, i)) : nlohmann::json(nullptr);
    configured[key] = c.configured[i];
    if (c.identifiable[i]) identifiable.push_back(key);
  }
  j["identifiable"] = identifiable;
  nlohmann::json despite = nlohmann::json::array();
  for (const std::string& text : calibrated_despite_mismatch(d)) despite.push_back(text);
  j["despite_mismatch"] = despite;
  j["configured"] = configured;
  j["at_mean_temperature_C"] = {
      {"psi_m_Wb", d.context.t_magnet.logged ? nlohmann::json(d.context.t_magnet.mean_C) : nlohmann::json(nullptr)},
      {"r_s_Ohm", d.context.t_winding.logged ? nlohmann::json(d.context.t_winding.mean_C) : nlohmann::json(nullptr)}};
  j["heldout_rms"] = c.heldout_rms_A;
  j["rpem"] = {{"psi_m_Wb", d.estimates.nominal_summary.psi_m_Wb},
               {"r_s_Ohm", d.estimates.nominal_summary.r_s_Ohm},
               {"method", d.estimates.method}};
  j["findings"] = calibration_findings(d);
  return j;
}

/// Samples per regime (core::kRegimes' names).
nlohmann::json regimes_json(const LogRegimes& r) {
  nlohmann::json j = nlohmann::json::object();
  for (const core::RegimeInfo& info : core::kRegimes) j[info.name] = r.counts.regimes[info.regime];
  return j;
}

/// Which loss the fits minimised, and why (docs/diagnose.md, "Outliers and the robust loss").
nlohmann::json loss_json(const Diagnosis& d) {
  const OutlierCheck& o = d.outliers;
  nlohmann::json j = {
      {"kind", d.least_squares ? "huber" : "least_squares"},
      {"outlier_test",
       {{"samples", o.test.samples},
        {"scale_A", o.test.scale_A},
        {"threshold_A", finite_json(o.test.threshold_A)},
        {"beyond", o.test.beyond},
        {"p_value", o.test.p_value},
        {"outliers", o.test.outliers}}},
      {"largest_shift", o.largest_shift},
      {"largest_shift_parameter", o.parameter.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.parameter)}};
  if (d.least_squares) {
    j["huber_threshold_A"] = o.loss.threshold_A;
    j["robust_runs"] = o.robust_runs;
    nlohmann::json ls = {{"effects", d.least_squares->found}, {"heldout_rms", d.least_squares->extended_heldout_rms_A}};
    for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
      ls[kCalibrated[i]] =
          d.least_squares->identifiable[i] ? nlohmann::json(d.least_squares->value[i]) : nlohmann::json(nullptr);
    }
    j["least_squares"] = ls;
  }
  return j;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f || !(f << text)) throw std::runtime_error("cannot write " + path);
}

/// |v| as a percentage with one decimal (0.0123 → "1.2").
std::string abs_percent(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", 100.0 * std::abs(v));
  return b;
}

/// v with four significant digits.
std::string four_significant(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

}  // namespace

std::vector<NamedValue> found_parameters(const Diagnosis& d, std::size_t j) {
  const Effect& e = d.selection.model.effects[j];
  return e.row->describe(e, d.extended_model, d.context);
}

const EstimatorCheck* estimator_check(const Diagnosis& d, std::size_t j) {
  const Effect& e = d.selection.found[j].effect;
  for (const EstimatorCheck& c : d.estimator_checks) {
    if (c.effect == e) return &c;
  }
  return nullptr;
}

// The allowance (docs/diagnose.md, "The calibrated baseline"; misfit_norm_A) at the final model: 0 where the
// constant is not excited (its column vanishes).
double mismatch_half_width(const Diagnosis& d, std::size_t i) {
  const double per_A = d.calibration.intervals.change_per_A[i];
  if (!std::isfinite(per_A)) return 0.0;
  const double floor = d.noise_floor.value_A.value_or(0.0);
  return per_A * misfit_norm_A(d.log->training_count(), d.selection.extended_heldout_rms_A, floor);
}

std::vector<std::string> calibrated_despite_mismatch(const Diagnosis& d) {
  std::vector<std::string> out;
  const Calibration& c = d.calibration;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (!c.identifiable[i] || c.identification[i] != Identification::kRejectsConfiguration) continue;
    const double rel = c.value[i] / c.configured[i] - 1.0;
    out.push_back(std::string(kCalibratedName[i]) + " " + four_significant(c.value[i]) + " (" + (rel > 0.0 ? "+" : "−") +
                  abs_percent(rel) + " % of the configuration's " + four_significant(c.configured[i]) +
                  "): its cluster-robust 95 % interval, ±" + abs_percent(c.intervals.half_width[i]) + " %, is wider than ±" +
                  abs_percent(kIdentifiedHalfWidth) +
                  " % — the model's misfit widens it — but even widened by the mismatch allowance, ±" +
                  abs_percent(mismatch_half_width(d, i)) + " %, it excludes the configured value: the log rejects it");
  }
  return out;
}

std::vector<std::string> calibration_findings(const Diagnosis& d) {
  std::vector<std::string> out;
  const Calibration& c = d.calibration;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (!c.identifiable[i]) continue;
    const double rel = c.configured[i] / c.value[i] - 1.0;  // the configuration against the calibrated value
    // Within its interval widened by the model mismatch allowance (or 0.5 %): not told from the configuration.
    const double hw = std::isfinite(c.intervals.half_width[i]) ? c.intervals.half_width[i] : 0.0;
    const double mismatch = mismatch_half_width(d, i);
    if (std::abs(c.value[i] / c.configured[i] - 1.0) <= std::max(hw + mismatch, 0.005)) continue;
    out.push_back(std::string("the configuration's ") + kCalibratedName[i] + " is " + abs_percent(rel) + " % " +
                  (rel > 0.0 ? "high" : "low"));
  }
  for (const std::string& b : calibrated_outside_bounds(d)) out.push_back(b);
  return out;
}

std::vector<std::string> calibrated_outside_bounds(const Diagnosis& d) {
  // ψm and R_s are the estimator's: a calibrated value outside D_M is one rpem estimate and rpemd hold at its bound.
  const core::EstimatorSettings& e = d.config.estimator;
  const std::array<std::array<double, 2>, 2> bounds{{{e.psi_m_min_Wb, e.psi_m_max_Wb}, {e.r_s_min_Ohm, e.r_s_max_Ohm}}};
  std::vector<std::string> out;
  for (std::size_t i = 0; i < bounds.size(); ++i) {
    const double v = d.calibration.value[i];
    if (!d.calibration.identifiable[i] || (v >= bounds[i][0] && v <= bounds[i][1])) continue;
    char text[400];
    std::snprintf(text, sizeof text,
                  "%s calibrated at %.6g lies outside estimator.bounds.%s [%.6g, %.6g], which extended.yaml keeps: rpem "
                  "estimate and rpemd would hold it at the bound; widen the bounds to hold it",
                  kCalibrated[i], v, kCalibrated[i], bounds[i][0], bounds[i][1]);
    out.emplace_back(text);
  }
  return out;
}

void write_diagnosis_json(const std::string& path, const Diagnosis& d, const std::string& config_path) {
  const LogData& log = *d.log;
  const Selection& s = d.selection;
  nlohmann::json out;
  const std::size_t used = log.used_count();
  out["log"] = {
      {"path", log.path},
      {"model", to_string(log.mode)},
      {"kind", log.averaged ? "averaged" : "phase_samples"},
      {"samples", log.size()},
      {"samples_used", used},
      {"excluded_idle", log.excluded_idle},
      {"excluded_transitional", log.excluded_transitional},
      {"duration_s", log.t_end_s - log.t_start_s},
      {"median_sample_interval_s", log.median_dt_s},
      {"i_d_range_A", {d.context.min_i_d_A, d.context.max_signed_i_d_A}},
      {"max_i_q_A", d.context.max_i_q_A},
      {"t_winding_span_K",
       d.context.t_winding.logged ? nlohmann::json(d.context.t_winding.span_K) : nlohmann::json(nullptr)},
      {"t_magnet_span_K", d.context.t_magnet.logged ? nlohmann::json(d.context.t_magnet.span_K) : nlohmann::json(nullptr)},
      {"regimes", regimes_json(d.regimes)},
      {"excluded_regime", d.regimes.excluded_used},
      {"estimator_resyncs", d.regimes.counts.resyncs},
      {"estimator_outliers", d.regimes.counts.outliers},
      {"r_s_on_assumed_frame", d.regimes.counts.regimes.r_s_on_assumed_frame},
      {"exclusion_explanations", d.regimes.explanations}};
  // A folder's logs, joined: each session's samples and its span on the joined time axis.
  nlohmann::json sessions = nlohmann::json::array();
  for (std::size_t j = 0; j < log.sessions(); ++j) {
    const std::size_t first = log.session_first[j], end = log.session_end(j);
    sessions.push_back({{"log", log.session_logs[j]},
                        {"first_sample", first},
                        {"samples", end - first},
                        {"t_first_s", log.t_s(first)},
                        {"t_last_s", log.t_s(end - 1)}});
  }
  out["log"]["sessions"] = sessions;
  out["machine_config"] = config_path;
  out["verdict"] = to_string(d.verdict.kind);
  out["noise_floor_A"] = optional_json(d.verdict.noise_floor_A);
  out["noise_floor"] = {
      {"second_differences", d.noise_floor.differences},
      {"unknown_reason", d.noise_floor.value_A ? nlohmann::json(nullptr) : nlohmann::json(d.noise_floor.unknown_reason)}};
  out["ratio"] = d.verdict.ratio ? finite_json(*d.verdict.ratio) : nlohmann::json(nullptr);
  out["findings"] = d.verdict.findings;
  out["loss"] = loss_json(d);

  out["baseline"] = {
      {"heldout_rms", d.baseline_heldout_rms_A},
      {"rms", d.statistics.rms_A.before},
      {"model_extensions", io::model_extensions_yaml(d.config)},
      {"rs_drift", drift_json(d.config.rs_drift)},
      {"psim_drift", drift_json(d.config.psim_drift)},
      {"drift_laws_replayed",
       {{"rs_drift", d.context.base.r_s_law.has_value()}, {"psim_drift", d.context.base.psi_m_law.has_value()}}},
      {"estimates", summary_json(d.estimates.nominal_summary)}};
  out["calibration"] = calibration_json(d);

  out["effects"] = nlohmann::json::array();
  for (std::size_t j = 0; j < s.found.size(); ++j) {
    const FoundEffect& f = s.found[j];
    nlohmann::json e = {{"name", f.effect.name()},
                        {"label", f.effect.label()},
                        {"params", params_json(found_parameters(d, j))},
                        {"heldout_rms_before", f.heldout_rms_before_A},
                        {"heldout_rms_after", f.heldout_rms_after_A},
                        {"gain_pct", f.gain_pct},
                        {"p_value", f.p_value}};
    if (const EstimatorCheck* c = estimator_check(d, j)) {
      e["kept"] = c->kept;
      e["estimator"] = c->applicable
                           ? nlohmann::json({{"heldout_eps_rms_with", c->with_A}, {"heldout_eps_rms_without", c->without_A}})
                           : nlohmann::json(nullptr);
    }
    out["effects"].push_back(e);
  }
  const double gain = s.start_heldout_rms_A > 0.0 ? 100.0 * (1.0 - s.extended_heldout_rms_A / s.start_heldout_rms_A) : 0.0;
  out["extended"] = {{"heldout_rms", s.extended_heldout_rms_A},
                     {"rms", d.statistics.rms_A.after},
                     {"gain_pct", gain},
                     {"estimates", summary_json(d.estimates.extended_summary)}};
  out["estimates_method"] = d.estimates.method;
  const std::string judged_against = d.estimates.judged_against();
  out["estimates_judged_against"] = judged_against.empty() ? nlohmann::json(nullptr) : nlohmann::json(judged_against);
  out["not_identifiable"] = nlohmann::json::array();
  for (const Unidentifiable& u : s.not_identifiable)
    out["not_identifiable"].push_back({{"effects", u.effects}, {"reason", u.reason}});
  for (const auto& [key, list] : {std::pair{"implausible", &s.implausible}, std::pair{"negligible", &s.negligible},
                                  std::pair{"withdrawn", &s.withdrawn}}) {
    out[key] = nlohmann::json::array();
    for (const ImplausibleEffect& i : *list) {
      out[key].push_back({{"effect", i.effect.label()},
                          {"params", params_json(i.parameters)},
                          {"gain_pct", i.gain_pct},
                          {"reason", i.why.reason},
                          {"more_likely", i.why.more_likely}});
    }
  }

  out["selection"] = nlohmann::json::array();
  for (const auto& round : s.rounds) {
    nlohmann::json r = nlohmann::json::array();
    for (const CandidateScore& c : round) {
      nlohmann::json cj = {{"effect", c.effect.label()}, {"screen_ssr_A2", c.screen_ssr}, {"fitted", c.fitted}};
      if (c.fitted) {
        cj["gain_pct"] = c.gain_pct;
        cj["p_value"] = c.p_value;
        cj["heldout_block_log_ratios"] = c.block_log_ratio;
        cj["scaled_start"] = c.start;
        cj["scaled_parameters"] = c.parameters;
      }
      r.push_back(cj);
    }
    out["selection"].push_back(r);
  }
  out["options"] = {{"min_gain_pct", d.options.selection.min_gain_pct},
                    {"max_p", d.options.selection.max_p},
                    {"reference_C", d.context.reference_C},
                    {"switching_frequency_Hz", d.context.switching_frequency_Hz},
                    {"blocks", log.blocks},
                    {"explained_ratio", kExplainedRatio},
                    {"min_noise_differences", kMinNoiseDifferences},
                    {"identified_half_width", kIdentifiedHalfWidth},
                    {"outlier_p", kOutlierP},
                    {"identifiable_half_width", kIdentifiableHalfWidth},
                    {"min_drift_span_K", kMinDriftSpan_K}};
  out["elapsed_s"] = d.elapsed_s;
  write_text(path, out.dump(2) + "\n");
}

namespace {

/// The estimator's start (`estimator.initial`, where the text gives it) at the calibrated ψm and R_s, so that the
/// next run starts where the diagnosis found the machine; not where one lies outside the bounds, which the
/// configuration's loader would refuse as a start (calibrated_outside_bounds says so in the header).
std::string with_calibrated_start(const std::string& text, const Diagnosis& d) {
  const core::EstimatorSettings& e = d.config.estimator;
  const std::array<std::array<double, 2>, 2> bounds{{{e.psi_m_min_Wb, e.psi_m_max_Wb}, {e.r_s_min_Ohm, e.r_s_max_Ohm}}};
  std::vector<std::pair<std::string, double>> start;
  for (std::size_t i = 0; i < bounds.size(); ++i) {
    const double v = d.calibration.value[i];
    if (d.calibration.identifiable[i] && v >= bounds[i][0] && v <= bounds[i][1]) start.emplace_back(kCalibrated[i], v);
  }
  return start.empty() ? text : io::replace_estimator_initial(text, start, "calibrated by rpem diagnose");
}

}  // namespace

void write_extended_yaml(const std::string& path, const Diagnosis& d, const std::string& config_text) {
  std::string header = "# Written by rpem diagnose: " + d.log->path +
                       " diagnosed with this configuration as the baseline;\n"
                       "# the machine's calibrated constants and the model_extensions section hold what it found\n"
                       "# (docs/diagnose.md, docs/model-extensions.md).\n";
  bool kept = false;
  for (const EstimatorCheck& c : d.estimator_checks) kept = kept || c.kept;
  if (!kept) header += "# No effect was added: the model_extensions are the input's.\n";
  for (const std::string& b : calibrated_outside_bounds(d)) header += "# Note: " + b + ".\n";
  std::vector<std::pair<std::string, double>> constants;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    const double v = d.extended_config.machine.*kCalibratedFields[i];
    if (d.calibration.identifiable[i] && v != d.config.machine.*kCalibratedFields[i])
      constants.emplace_back(kCalibrated[i], v);
  }
  const std::string text =
      constants.empty() ? config_text : io::replace_machine_values(config_text, constants, "calibrated by rpem diagnose");
  write_text(path, header + io::replace_model_extensions(with_calibrated_start(text, d),
                                                         io::model_extensions_yaml(d.extended_config)));
}

}  // namespace rpem::analysis
