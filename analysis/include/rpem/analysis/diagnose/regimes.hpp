#pragma once
// Each sample's regime (core/regime.hpp, docs/derivations.md §13) decided as `rpem estimate` and rpemd
// decide it: the configured estimator — DriveEstimator over phase samples, AveragedDriveEstimator over
// averaged windows — runs over the log with the same classifier and chain, and the regime of each step is
// the sample's. The samples it excludes (bridge off, not locked, transient, not finite) enter no fit of the
// diagnosis (exclude_regimes); the report shows the counts, a timeline coloured by regime and, where a rule
// took more than a tenth of the samples, which rule and which key changes it (io::exclusion_explanations).

#include <string>
#include <vector>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/monitor.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/sample_counts.hpp"

namespace rpem::analysis {

struct LogRegimes {
  std::vector<core::Regime> regime;  ///< per sample of the log
  io::SampleCounts counts;           ///< per regime, and the run's resyncs and outlier skips
  /// Every rule that took more than io::kExplainedShare of the samples out — a regime's, the estimator's
  /// resynchronisation, the steady-state replay's idle and transitional rows — with the key that changes it.
  std::vector<std::string> explanations;
  std::size_t excluded_used = 0;  ///< excluded samples the diagnosis would otherwise have used
  /// The data's noise as the classifier learnt it over the whole log: σ² of u, i and n per unit, the
  /// quantisation of their resolution included (core::RegimeClassifier::current_noise).
  core::RegimeNoise noise_pu{};
};

/// Runs the configured estimator over `log` (its rows; an averaged log's windows) and records each
/// sample's regime. `monitor` (if any) is told the samples run and asked, every kMonitorSamples, whether to
/// stop (then Interrupted is thrown).
[[nodiscard]] LogRegimes classify_regimes(const LogData& log, const io::MachineConfig& config, Monitor* monitor = nullptr);

/// Takes the samples `regimes` excludes out of log.used (counting those newly taken out).
void exclude_regimes(LogData& log, LogRegimes& regimes);

}  // namespace rpem::analysis
