#pragma once
// `rpem diagnose` as a library call (docs/diagnose.md): replay the nominal model on a log's inputs,
// find which catalogue effects explain what it gets wrong, extend the model with them, measure the
// gain on held-out data and on the estimator, and keep everything the report needs.

#include <memory>
#include <string>

#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/diagnose/estimator_comparison.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/residual_statistics.hpp"
#include "rpem/analysis/diagnose/selection.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {

struct DiagnoseOptions {
  double reference_C = 20.0;            ///< temperature at which the configuration's r_s and ψm hold
  double switching_frequency_Hz = 0.0;  ///< for t_dead_s (0: the configuration's, else unknown)
  SelectionOptions selection;
};

struct Diagnosis {
  DiagnoseOptions options;
  std::unique_ptr<LogData> log;         ///< owned: the replays refer to it
  io::MachineConfig config;             ///< as given
  io::MachineConfig extended_config;    ///< with the found effects (extended.yaml)
  EffectContext context;
  Selection selection;
  ExtendedModel extended_model;
  ReplayOutput nominal_replay, extended_replay;
  ResidualStatistics statistics;
  EstimatorComparison estimates;
  double elapsed_s = 0.0;
};

/// `truth` may be empty (unknown).
[[nodiscard]] Diagnosis diagnose(LogData log, const io::MachineConfig& config, const DiagnoseOptions& options,
                                 const ParameterTrack& truth = {});

}  // namespace rpem::analysis
