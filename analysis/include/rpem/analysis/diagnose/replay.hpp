#pragma once
// The simulation on the measured inputs: a model (baseline or extended) driven by the logged voltage
// commands, angle and speed predicts the currents, and the residual is what the log says minus what
// the model says, both in the log's own measured space (dq at the logged angle, A):
//   transient logs   — the open-loop discrete predictor (core::predict, trapezoidal; the estimator's
//                      own predictor), started from the measurement at the start of every block (and
//                      after gaps), so that each block is replayed on its own and a fit needs only the
//                      training blocks;
//   steady-state logs — the closed-form steady state (core::steady_state_current) per sample.
// The model extensions enter exactly as the estimator applies them (core::SampleConditioner), and
// leave again through its observation model, so every model is judged against the same numbers.

#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/types.hpp"

namespace rpem::analysis {

struct ReplayOutput {
  std::vector<core::Vec2> residual_A;  ///< logged − model; zero where not valid
  std::vector<core::Vec2> model_A;     ///< the model's current as the log would show it
  std::vector<bool> valid;             ///< a prediction exists (replayed, not a sync sample, not excluded)
};

/// Which blocks a replay covers.
enum class Blocks { kAll, kTraining, kHeldout };

class ModelReplay {
 public:
  /// `rated`: the per-unit base's name plate.
  ModelReplay(const LogData& log, const core::RatedData& rated);

  /// Replays `blocks` of the log with `model`. Thread-safe (const); allocates only the output.
  void run(const ExtendedModel& model, ReplayOutput& out, Blocks blocks = Blocks::kAll) const;

  [[nodiscard]] const LogData& log() const noexcept { return log_; }

 private:
  /// A stretch of samples replayed in one chain: warm-up samples (conditioner only) from `begin`, the
  /// block's own from `first`.
  struct Stretch {
    std::size_t begin, first, end;
  };
  [[nodiscard]] bool selected(std::size_t k, Blocks blocks) const noexcept;
  void run_transient(const ExtendedModel& model, ReplayOutput& out, Blocks blocks) const;
  void run_steady_state(const ExtendedModel& model, ReplayOutput& out, Blocks blocks) const;

  const LogData& log_;
  core::PerUnitBase base_;
  double max_interval_s_;
  std::vector<Stretch> blocks_;  ///< one per block, in order
  std::vector<core::Rotation> logged_rotation_;  ///< transient logs: each sample's logged angle, once
};

}  // namespace rpem::analysis
