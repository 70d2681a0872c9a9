#pragma once
// What `rpem diagnose` writes (docs/diagnose.md, "Outputs"): diagnosis.json, extended.yaml (the input
// configuration with the found effects as model_extensions, which `rpem estimate --config` and rpemd
// take as they are), the figures and report.md / report.html.

#include <string>
#include <vector>

#include "rpem/analysis/diagnose/diagnosis.hpp"

namespace rpem::analysis {

void write_diagnosis_json(const std::string& path, const Diagnosis& d, const std::string& config_path);

/// `config_text`: the input configuration file's text (its model_extensions section is replaced).
void write_extended_yaml(const std::string& path, const Diagnosis& d, const std::string& config_text);

/// The figures; returns their file names (relative to `dir`).
[[nodiscard]] std::vector<std::string> write_diagnose_figures(const std::string& dir, const Diagnosis& d);

/// The log's timeline coloured by regime (speed and current amplitude against time), `dir`/regimes.png, as
/// the diagnosis draws it; `rpem figures --log` draws it without a diagnosis. Returns the file name.
std::string write_regime_timeline(const std::string& dir, const LogData& log, const LogRegimes& regimes, int pole_pairs);

void write_diagnose_report(const std::string& dir, const Diagnosis& d, const std::string& config_path);

/// The found effect j's parameters in SI (its row's describe() of the final joint fit).
[[nodiscard]] std::vector<NamedValue> found_parameters(const Diagnosis& d, std::size_t j);

/// The model mismatch allowance of calibrated constant i, relative (e.g. 0.10 for ±10 %): the largest bias
/// the misfit the final model leaves above the noise floor could put into it (`<key>_mismatch_rel`).
[[nodiscard]] double mismatch_half_width(const Diagnosis& d, std::size_t i);

/// One sentence per constant calibrated despite a large mismatch (Identification::kRejectsConfiguration): its
/// interval wider than ±10 % but excluding the configured value ("calibrated despite a large mismatch: …").
[[nodiscard]] std::vector<std::string> calibrated_despite_mismatch(const Diagnosis& d);

/// What the calibration says about the configuration, one sentence per identifiable constant whose
/// configured value lies outside the calibrated 95 % interval widened by its mismatch allowance (e.g. "the configuration's ψm is 5.1 % high").
[[nodiscard]] std::vector<std::string> calibration_findings(const Diagnosis& d);
/// One sentence per identifiable ψm or R_s calibrated outside the configuration's estimator.bounds (D_M), which
/// extended.yaml keeps: the estimator would hold it at the bound. Part of calibration_findings, and a note in
/// extended.yaml's header.
[[nodiscard]] std::vector<std::string> calibrated_outside_bounds(const Diagnosis& d);

/// The estimator check of the found effect j (nullptr if none).
[[nodiscard]] const EstimatorCheck* estimator_check(const Diagnosis& d, std::size_t j);

}  // namespace rpem::analysis
