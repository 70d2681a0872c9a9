#include "rpem/analysis/diagnose/diagnosis.hpp"

#include <algorithm>
#include <chrono>

#include "rpem/analysis/diagnose/replay.hpp"

namespace rpem::analysis {
namespace {

/// How a drift of the model is recorded in a configuration: a law against temperature (referred to
/// `reference_C`, value_ref the model's constant), a change over the log, or the input's own entry.
io::ParameterDrift recorded_drift(const io::ParameterDrift& input, const std::optional<core::DriftLaw>& law, double trend,
                                  double value, double reference_C) {
  if (law) return {recorded_law(*law, value, reference_C), std::nullopt};
  if (trend != 0.0) return {std::nullopt, trend / (1.0 - 0.5 * trend)};
  return input;
}

/// The effects of `set` that `keep` admits, at their jointly fitted values, with the calibrated constants.
EffectSet subset(const EffectSet& set, const std::vector<bool>& keep) {
  EffectSet s = set;
  s.effects.clear();
  s.parameters.clear();
  for (std::size_t j = 0; j < set.effects.size(); ++j) {
    if (!keep[j]) continue;
    s.effects.push_back(set.effects[j]);
    s.parameters.push_back(set.parameters[j]);
  }
  return s;
}

/// Greedy, in the order found: an effect stays in extended.yaml only if the RPEM estimator with it (and
/// the effects kept before it) predicts the held-out blocks at least as well as without it.
std::vector<EstimatorCheck> check_estimator(const Diagnosis& d, const WorkPool& pool, std::vector<bool>& keep) {
  constexpr double kTolerance = 1e-3;  // "at least as well": within rounding of the RMS
  std::vector<EstimatorCheck> checks;
  const EffectSet& model = d.selection.model;
  keep.assign(model.effects.size(), true);
  if (d.log->mode != ModelMode::kTransient) {
    for (const Effect& e : model.effects) checks.push_back({e, false, 0.0, 0.0, true});
    return checks;
  }
  std::vector<bool> trial(model.effects.size(), false);
  auto rms_with = [&](const std::vector<bool>& k) {
    const ExtendedModel m = subset(model, k).model(d.context);
    return estimator_heldout_rms_A(*d.log, config_of(d.config, m, d.calibration.identifiable, d.context.reference_C),
                                   d.options.monitor);
  };
  // The model without any and with the first: both needed whatever is kept, so at once.
  double current = 0.0, first_with = 0.0;
  if (!model.effects.empty()) {
    pool.parallel_for(2, [&](std::size_t i) {
      std::vector<bool> k(model.effects.size(), false);
      k[0] = i == 1;
      (i == 0 ? current : first_with) = rms_with(k);
    });
  }
  for (std::size_t j = 0; j < model.effects.size(); ++j) {
    trial[j] = true;
    const double with = j == 0 ? first_with : rms_with(trial);
    EstimatorCheck c{model.effects[j], true, with, current, with <= current * (1.0 + kTolerance)};
    if (c.kept) {
      current = with;
    } else {
      trial[j] = false;
    }
    keep[j] = c.kept;
    checks.push_back(c);
  }
  return checks;
}

/// An effect that the readmitted constants leave physically negligible was standing in for them: it is
/// taken out of the named effects and the model refitted.
void prune_negligible(const EffectFitter& fitter, Diagnosis& d) {
  Selection& s = d.selection;
  const ExtendedModel m = s.model.model(d.context);
  EffectSet kept = s.model;
  std::vector<FoundEffect> found;
  for (const FoundEffect& f : s.found) {
    const EffectRow& row = *f.effect.row;
    if (row.negligible && row.negligible(f.effect, m, d.context)) {
      kept = kept.without(f.effect);
      s.negligible.push_back({f.effect,
                              row.describe(f.effect, m, d.context),
                              f.gain_pct,
                              {"negligible once the calibrated constants were refitted with the effects found",
                               "part of the calibrated constants it stood in for"}});
      continue;
    }
    found.push_back(f);
  }
  if (found.size() == s.found.size()) return;
  s.found = found;
  s.model = fitter.fit(kept);
  s.extended_heldout_rms_A = rms(fitter.heldout(s.model));
}

/// The calibrated baseline and the effects found from it, all fitted with `fitter`'s loss (docs/diagnose.md,
/// "The calibrated baseline", "How an effect is accepted"); fills d.calibration and d.selection.
void calibrate_and_select(const EffectFitter& fitter, double floor, Diagnosis& d) {
  Monitor* monitor = d.options.monitor;
  // The calibrated baseline: the constants the log's excitation pins down, fitted on the training blocks.
  if (monitor)
    monitor->stage(
        fitter.loss().robust() ? "calibrating the constants (robust loss)" : "calibrating the configuration's constants", 0);
  EffectSet start;
  const CalibrationIntervals excitation = fitter.intervals(start, floor);
  std::array<bool, kCalibrated.size()> admissible{};
  const std::array<std::string_view, kCalibrated.size()> withheld = withheld_constants(d.context);
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    admissible[i] = excitation.excitation_half_width[i] <= kIdentifiableHalfWidth && withheld[i].empty();
    start.calibrated[i] = d.calibration.identifiable[i] = admissible[i];
    d.calibration.configured[i] = d.context.base.machine.*kCalibratedFields[i];
  }
  if (start.free_calibration() > 0) start = fitter.fit(start);
  // A constant the excitation would pin down but whose fit the model's own errors move far (its
  // cluster-robust interval wide and holding the configured value, or at the ±50 % bound) is not identified:
  // it stays configured.
  if (start.free_calibration() > 0) {
    const CalibrationIntervals fitted = fitter.intervals(start, floor);
    const double misfit = misfit_norm_A(fitter.training_samples(), rms(fitter.heldout(start)), floor);
    bool dropped = false;
    for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
      if (!start.calibrated[i] || identification(start, fitted, i, misfit) != Identification::kNot) continue;
      start.calibrated[i] = d.calibration.identifiable[i] = false;
      start.calibration[i] = 0.0;
      dropped = true;
    }
    if (dropped && start.free_calibration() > 0) start = fitter.fit(start);
  }
  d.calibration.heldout_rms_A = rms(fitter.heldout(start));

  d.selection = select_effects(fitter, d.options.selection, start, floor, admissible);
  if (monitor) monitor->stage("refitting the model found", 0);
  prune_negligible(fitter, d);
  // A drift law found brings the constant it is referred to (EffectRow::frees_constant).
  d.calibration.intervals = fitter.intervals(d.selection.model, floor);
  const double misfit = misfit_norm_A(fitter.training_samples(), d.selection.extended_heldout_rms_A, floor);
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    d.calibration.identifiable[i] = d.selection.model.calibrated[i];
    d.calibration.identification[i] = d.calibration.identifiable[i]
                                          ? identification(d.selection.model, d.calibration.intervals, i, misfit)
                                          : Identification::kNot;
  }
  d.extended_model = d.selection.model.model(d.context);
  for (std::size_t i = 0; i < kCalibrated.size(); ++i)
    d.calibration.value[i] = d.extended_model.machine.*kCalibratedFields[i];
}

/// The diagnosis again under Huber's loss (docs/diagnose.md, "Outliers and the robust loss"), after the
/// least-squares one (kept in d.least_squares for the report). b from the least-squares model's residuals is
/// too wide where the outliers pulled its bulk too: it is re-estimated from each robust diagnosis' own final
/// residuals until it settles within 10 % (at most kRobustRuns).
void diagnose_robustly(const EffectFitter& least_squares, double floor, Diagnosis& d) {
  LeastSquaresResult ls;
  for (const FoundEffect& f : d.selection.found) ls.found.push_back(f.effect.label());
  ls.value = d.calibration.value;
  ls.identifiable = d.calibration.identifiable;
  ls.extended_heldout_rms_A = d.selection.extended_heldout_rms_A;
  d.least_squares = ls;
  for (int run = 1; run <= kRobustRuns; ++run) {
    const EffectFitter robust = least_squares.with_loss(d.outliers.loss);
    d.baseline_heldout_rms_A = rms(robust.heldout(EffectSet{}));
    calibrate_and_select(robust, floor, d);
    d.outliers.robust_runs = run;
    std::vector<double> r;
    least_squares.training_residuals(d.selection.model, r);
    const double settled = test_outliers(r).threshold_A;
    if (std::abs(settled / d.outliers.loss.threshold_A - 1.0) < 0.1 || run == kRobustRuns) break;
    d.outliers.loss.threshold_A = settled;
  }
}

}  // namespace

io::MachineConfig config_of(const io::MachineConfig& input, const ExtendedModel& model,
                            const std::array<bool, kCalibrated.size()>& constants, double reference_C) {
  io::MachineConfig c = input;
  c.estimator.extensions = model.extensions;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (constants[i]) c.machine.*kCalibratedFields[i] = model.machine.*kCalibratedFields[i];
  }
  c.rs_drift = recorded_drift(input.rs_drift, model.r_s_law, model.r_s_trend, model.machine.r_s_Ohm, reference_C);
  c.psim_drift = recorded_drift(input.psim_drift, model.psi_m_law, model.psi_m_trend, model.machine.psi_m_Wb, reference_C);
  // Under a law the machine's constant is its value at the law's reference temperature.
  if (model.r_s_law && constants[1]) c.machine.r_s_Ohm = c.rs_drift.law->value_ref;
  if (model.psi_m_law && constants[0]) c.machine.psi_m_Wb = c.psim_drift.law->value_ref;
  return c;
}

Diagnosis diagnose(LogData log, const io::MachineConfig& config, const DiagnoseOptions& options,
                   const ParameterTrack& truth) {
  const auto start_time = std::chrono::steady_clock::now();
  Diagnosis d;
  d.options = options;
  d.log = std::make_unique<LogData>(std::move(log));
  d.config = config;
  Monitor none;
  Monitor& monitor = options.monitor ? *options.monitor : none;
  const std::uint64_t n = d.log->size();
  // Each sample's regime, as the estimator decides it; the excluded ones enter no fit.
  monitor.stage("classifying the samples' regimes", n);
  d.regimes = classify_regimes(*d.log, config, options.monitor);
  exclude_regimes(*d.log, d.regimes);
  for (std::string& why : left_out_explanations(*d.log)) d.regimes.explanations.push_back(std::move(why));
  require_samples_to_fit(*d.log, d.regimes.explanations);
  const double f_sw = options.switching_frequency_Hz > 0.0 ? options.switching_frequency_Hz
                                                           : config.estimator.extensions.switching_frequency_Hz;
  const ExtendedModel base =
      make_base_model(config.machine, config.estimator.extensions, config.rs_drift.law, config.psim_drift.law, *d.log);
  d.context = EffectContext::of(*d.log, config.machine, base, options.reference_C, f_sw);
  d.context.frame_sensorless = config.estimator.regimes.sensorless;

  const WorkPool pool(std::max(1, options.jobs));
  const ModelReplay replay(*d.log, config.machine.rated, pool, options.monitor);
  monitor.stage("replaying the configuration", 2 * n);
  const EffectFitter least_squares(replay, d.context);

  // The configuration as it is, and the noise floor of its residual (the same for every model).
  const BaselinePass baseline = baseline_pass(replay, d.context, base);
  d.baseline_heldout_rms_A = rms(least_squares.heldout(EffectSet{}));
  d.noise_floor = baseline.noise_floor;
  const double floor = d.noise_floor.for_fits_A();

  calibrate_and_select(least_squares, floor, d);
  // Outliers that move the least-squares fit: everything again under the robust loss.
  monitor.stage("checking for outliers", 0);
  d.outliers = check_outliers(least_squares, d.selection.model, d.calibration.intervals);
  if (d.outliers.influential) diagnose_robustly(least_squares, floor, d);

  const bool transient = d.log->mode == ModelMode::kTransient;
  monitor.stage("checking the effects on the estimator", transient ? (d.selection.model.effects.size() + 1) * n : 0);
  std::vector<bool> keep;
  d.estimator_checks = check_estimator(d, pool, keep);
  d.extended_config =
      config_of(config, subset(d.selection.model, keep).model(d.context), d.calibration.identifiable, options.reference_C);

  // The estimator's two runs and the whole-log comparison, at once.
  monitor.stage("comparing the models over the whole log", (transient ? 2 * n : 0) + 2 * n);
  pool.parallel_for(2, [&](std::size_t i) {
    if (i == 0) {
      d.estimates = compare_estimates(*d.log, config, d.extended_config, d.extended_model, d.context, truth,
                                      d.regimes.noise_pu, pool, options.monitor);
    } else {
      comparison_pass(replay, d.context, base, d.extended_model, baseline, d.statistics, d.figures);
    }
  });
  d.verdict = verdict(d.selection.extended_heldout_rms_A, d.noise_floor, d.statistics);
  d.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return d;
}

}  // namespace rpem::analysis
