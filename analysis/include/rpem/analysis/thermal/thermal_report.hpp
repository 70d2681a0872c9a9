#pragma once
// What `rpem thermal fit` writes (docs/thermal.md): thermal.yaml (the fitted section, with the fit's
// figures as comments), and with --report DIR: report.md, fit.json and predictions.csv (the model alone
// and what was observed, per step of the filter).

#include <string>

#include "rpem/analysis/thermal/thermal_fit.hpp"

namespace rpem::analysis {

/// thermal.yaml: a comment header (log, configuration, fit and held-out RMS, identifiability) and the section.
void write_thermal_yaml(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record,
                        const std::string& config_name);
void write_thermal_fit_json(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record,
                            const std::string& config_name);
void write_thermal_fit_report(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record,
                              const std::string& config_name);
/// t, the model's node temperatures, the magnet and winding temperatures the estimates imply (their laws'
/// inverses where they are observations, else empty), the winding sensor, the coolant, the copper loss and the session
/// (0, 1, …: ThermalRecord::session_first_step).
void write_thermal_predictions(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record);

/// What the training part observed of a signal, for every output: "24.9–25.0 °C", or "none" where it has none of it.
[[nodiscard]] std::string training_span(const SignalFit& s);

}  // namespace rpem::analysis
