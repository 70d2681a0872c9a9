#pragma once
// The simulation on the measured inputs: a model (nominal or extended) driven by the logged voltage
// commands, angle and speed predicts the currents, and the residual is what the log says minus what
// the model says, both in the log's own measured space (dq at the logged angle, A):
//   transient logs   — the open-loop discrete predictor (core::predict, trapezoidal; the estimator's
//                      own predictor), started from the first measurement and resynchronised only
//                      across gaps;
//   steady-state logs — the closed-form steady state (core::steady_state_current) per sample.
// The model extensions enter exactly as the estimator applies them (core::SampleConditioner), and
// leave again through its observation model, so every model is judged against the same numbers.

#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/core/types.hpp"

namespace rpem::analysis {

struct ReplayOutput {
  std::vector<core::Vec2> residual_A;  ///< logged − model; zero where not valid
  std::vector<core::Vec2> model_A;     ///< the model's current as the log would show it
  std::vector<bool> valid;             ///< a prediction exists (not a sync sample, not excluded)
};

class ModelReplay {
 public:
  ModelReplay(const LogData& log, const core::MachineSi& machine, double reference_C);

  /// Replays the whole log with `model`. Thread-safe (const); allocates only the output.
  void run(const ExtendedModel& model, ReplayOutput& out) const;

  [[nodiscard]] const LogData& log() const noexcept { return log_; }

 private:
  /// ψm and r_s of the nominal machine under the model's drifts at sample k, pu.
  void drifted(const ExtendedModel& model, std::size_t k, core::MachinePu& m) const noexcept;
  void run_transient(const ExtendedModel& model, ReplayOutput& out) const;
  void run_steady_state(const ExtendedModel& model, ReplayOutput& out) const;

  const LogData& log_;
  core::PerUnitBase base_;
  core::MachinePu nominal_;
  double reference_C_;
  double max_interval_s_;
};

}  // namespace rpem::analysis
