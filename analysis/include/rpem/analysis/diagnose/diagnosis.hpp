#pragma once
// `rpem diagnose` as a library call (docs/diagnose.md): replay the configuration's whole model (the
// baseline) on a log's inputs, calibrate the machine's constants the log identifies, find which
// catalogue effects explain what the calibrated baseline still gets wrong, extend the model with them,
// measure the gain on held-out data and on the estimator, and judge what is left against the noise floor.

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/diagnose/estimator_comparison.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/outliers.hpp"
#include "rpem/analysis/diagnose/regimes.hpp"
#include "rpem/analysis/diagnose/residual_statistics.hpp"
#include "rpem/analysis/diagnose/selection.hpp"
#include "rpem/analysis/diagnose/verdict.hpp"
#include "rpem/analysis/diagnose/whole_log.hpp"
#include "rpem/core/thermal.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {

struct DiagnoseOptions {
  double reference_C = core::kMaterialReference_C;  ///< temperature to which found drift laws are referred
  double switching_frequency_Hz = 0.0;              ///< for t_dead_s (0: the configuration's, else unknown)
  SelectionOptions selection;
  /// Threads that replay blocks and fit candidates (the results are the same for any number).
  int jobs = 1;
  /// Told the stages and the work done, asked whether to stop (nullptr: none).
  Monitor* monitor = nullptr;
};

/// The calibrated baseline (docs/diagnose.md, "The calibrated baseline"), kCalibrated order.
struct Calibration {
  std::array<double, kCalibrated.size()>
      configured{};  ///< the configuration's (ψm, R_s at the log's mean temperature under a drift law)
  std::array<double, kCalibrated.size()> value{};  ///< calibrated (configured where not identifiable)
  std::array<bool, kCalibrated.size()> identifiable{};
  /// How each identifiable constant is identified at the final model (kRejectsConfiguration: calibrated
  /// despite a large mismatch, docs/diagnose.md).
  std::array<Identification, kCalibrated.size()> identification{};
  CalibrationIntervals intervals;  ///< at the final model
  double heldout_rms_A = 0.0;      ///< the calibrated baseline's held-out residual
};

/// Whether a found effect helps the estimator (docs/diagnose.md, "An extension must help the estimator").
struct EstimatorCheck {
  Effect effect;
  bool applicable = false;  ///< a recursive-estimator check exists (transient logs)
  double with_A = 0.0;      ///< held-out RMS of ε with the effects kept so far and this one
  double without_A = 0.0;   ///< … with the effects kept so far
  bool kept = true;
};

/// What the least-squares diagnosis found where outliers moved it and the diagnosis was run again under the
/// robust loss (docs/diagnose.md, "Outliers and the robust loss").
struct LeastSquaresResult {
  std::vector<std::string> found;                  ///< effect labels
  std::array<double, kCalibrated.size()> value{};  ///< calibrated constants (configured where not identifiable)
  std::array<bool, kCalibrated.size()> identifiable{};
  double extended_heldout_rms_A = 0.0;  ///< its final model's held-out RMS (least squares)
};

struct Diagnosis {
  DiagnoseOptions options;
  std::unique_ptr<LogData> log;       ///< owned: the replays refer to it
  LogRegimes regimes;                 ///< each sample's regime; the excluded ones are out of log->used
  io::MachineConfig config;           ///< as given
  io::MachineConfig extended_config;  ///< calibrated constants and the kept effects (extended.yaml)
  EffectContext context;
  double baseline_heldout_rms_A = 0.0;  ///< the configuration's whole model, as it is
  NoiseFloor noise_floor;               ///< of the configuration's residual (the same for every model)
  OutlierCheck outliers;                ///< whether outliers moved the least-squares fit (then the loss is robust)
  std::optional<LeastSquaresResult> least_squares;  ///< set where the robust loss replaced least squares
  Calibration calibration;
  Selection selection;
  std::vector<EstimatorCheck> estimator_checks;  ///< one per found effect, in the order found
  ExtendedModel extended_model;                  ///< the calibrated baseline with every found effect
  ResidualStatistics statistics;                 ///< before: the baseline; after: the extended model
  FigureData figures;                            ///< what the figures draw (whole_log.hpp)
  Verdict verdict;
  EstimatorComparison estimates;  ///< nominal: the configuration; extended: extended_config
  double elapsed_s = 0.0;
};

/// `truth` may be empty (unknown). Throws Interrupted where options.monitor asks it to stop.
[[nodiscard]] Diagnosis diagnose(LogData log, const io::MachineConfig& config, const DiagnoseOptions& options,
                                 const ParameterTrack& truth = {});

/// The configuration a model stands for: `input` with the model's identifiable constants, extensions and
/// drift laws (referred to `reference_C`).
[[nodiscard]] io::MachineConfig config_of(const io::MachineConfig& input, const ExtendedModel& model,
                                          const std::array<bool, kCalibrated.size()>& constants, double reference_C);

}  // namespace rpem::analysis
