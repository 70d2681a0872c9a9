#include "rpem/analysis/diagnose/diagnosis.hpp"

#include <chrono>

#include "rpem/analysis/diagnose/replay.hpp"

namespace rpem::analysis {
namespace {

double value_of(const std::vector<NamedValue>& values, const char* name) {
  for (const NamedValue& v : values) {
    if (v.name == name) return v.value;
  }
  return 0.0;
}

/// A found drift as the configuration records it.
io::ParameterDrift recorded_drift(const std::vector<NamedValue>& values, bool temperature) {
  io::ParameterDrift d;
  if (temperature) {
    d.law = core::DriftLaw{value_of(values, "coeff_per_K"), value_of(values, "reference_C")};
  } else {
    d.rel_change = value_of(values, "rel_change");
  }
  return d;
}

}  // namespace

Diagnosis diagnose(LogData log, const io::MachineConfig& config, const DiagnoseOptions& options,
                   const ParameterTrack& truth) {
  const auto start = std::chrono::steady_clock::now();
  Diagnosis d;
  d.options = options;
  d.log = std::make_unique<LogData>(std::move(log));
  d.config = config;
  const double f_sw = options.switching_frequency_Hz > 0.0 ? options.switching_frequency_Hz
                                                          : config.estimator.extensions.switching_frequency_Hz;
  d.context = EffectContext::of(*d.log, config.machine, config.estimator.extensions, options.reference_C, f_sw);

  const ModelReplay replay(*d.log, config.machine, options.reference_C);
  const EffectFitter fitter(replay, d.context);
  d.selection = select_effects(fitter, options.selection);

  d.extended_model = d.selection.model.model(d.context);
  d.extended_config = config;
  d.extended_config.estimator.extensions = d.extended_model.extensions;
  for (std::size_t j = 0; j < d.selection.model.effects.size(); ++j) {
    const Effect& e = d.selection.model.effects[j];
    if (e.kind != EffectKind::kRsDrift && e.kind != EffectKind::kPsimDrift) continue;
    const auto values = describe(e, d.selection.model.parameters[j].data(), d.context);
    if (e.kind == EffectKind::kRsDrift) {
      d.extended_config.rs_drift = recorded_drift(values, d.context.t_winding);
    } else {
      d.extended_config.psim_drift = recorded_drift(values, d.context.t_magnet);
    }
  }

  replay.run(EffectSet{}.model(d.context), d.nominal_replay);
  replay.run(d.extended_model, d.extended_replay);
  d.statistics = residual_statistics(*d.log, d.context, d.nominal_replay, d.extended_replay);
  d.estimates = compare_estimates(*d.log, config, d.extended_config, d.extended_model, d.context, truth);
  d.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

}  // namespace rpem::analysis
