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

void write_diagnose_report(const std::string& dir, const Diagnosis& d, const std::string& config_path);

/// The found effect j's parameters in SI (describe() of the final joint fit).
[[nodiscard]] std::vector<NamedValue> found_parameters(const Diagnosis& d, std::size_t j);

}  // namespace rpem::analysis
