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
//
// A replay streams: several models go through a block together, sample by sample (the sample, its logged
// angle's rotation and its logged current are computed once for all of them), and each sample's residuals
// are handed to a visitor, never stored whole. Blocks are independent, so a pass over many blocks runs
// them on a WorkPool and its caller combines the blocks' results in block order (the same for any number
// of threads).

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/monitor.hpp"
#include "rpem/analysis/work_pool.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/types.hpp"

namespace rpem::analysis {

/// One model's prediction at one sample.
struct ModelSample {
  core::Vec2 residual_A = core::Vec2::Zero();  ///< logged − model; zero where not valid
  core::Vec2 model_A = core::Vec2::Zero();     ///< the model's current as the log would show it
  bool valid = false;                          ///< a prediction exists (replayed, not a sync sample, not excluded)
};

/// A whole replay, every sample (tests and small logs; a diagnosis streams instead).
struct ReplayOutput {
  std::vector<core::Vec2> residual_A;  ///< logged − model; zero where not valid
  std::vector<core::Vec2> model_A;     ///< the model's current as the log would show it
  std::vector<bool> valid;
};

/// Which blocks a replay covers.
enum class Blocks { kAll, kTraining, kHeldout };

class ModelReplay {
 public:
  /// What a visitor sees of one sample: its index and each model's prediction (in the order given).
  using Visit = std::function<void(std::size_t k, std::span<const ModelSample> models)>;

  /// `rated`: the per-unit base's name plate. `pool` runs the blocks of a pass; `monitor` (if any) is told the
  /// samples replayed (per model) and asked, before each block, whether to stop (then Interrupted is thrown).
  ModelReplay(const LogData& log, const core::RatedData& rated, const WorkPool& pool = WorkPool::serial(),
              Monitor* monitor = nullptr);

  /// Replays `models` together over block b (index into the log's blocks; its warm-up samples first) and
  /// calls `visit` for each of its samples that takes part (LogData::used). Thread-safe (const).
  void replay_block(int b, std::span<const ExtendedModel> models, const Visit& visit) const;

  /// The blocks `blocks` selects that hold samples, in order.
  [[nodiscard]] std::vector<int> blocks(Blocks which) const;

  /// Runs per_block(i, b) for the i-th of `blocks` on the pool (checking between blocks whether to stop).
  void for_blocks(const std::vector<int>& blocks, const std::function<void(std::size_t i, int b)>& per_block) const;

  /// Replays `blocks` of the log with `model`, every sample kept (tests and small logs). Thread-safe (const).
  void run(const ExtendedModel& model, ReplayOutput& out, Blocks which = Blocks::kAll) const;

  [[nodiscard]] const LogData& log() const noexcept { return log_; }
  [[nodiscard]] const WorkPool& pool() const noexcept { return pool_; }
  [[nodiscard]] Monitor* monitor() const noexcept { return monitor_; }

 private:
  class Chain;
  /// One chain per distinct model (a model the same as an earlier one bit for bit steps none of its own):
  /// appends them to `chains` and returns each model's chain.
  std::vector<std::size_t> distinct_chains(std::span<const ExtendedModel> models, std::vector<Chain>& chains) const;
  /// Per chain, the chain whose conditioner's samples it takes: the first that conditions alike (itself if
  /// none before it does).
  static std::vector<std::size_t> shared_conditioners(const std::vector<Chain>& chains);

  const LogData& log_;
  core::PerUnitBase base_;
  double max_interval_s_;
  const WorkPool& pool_;
  Monitor* monitor_;
};

}  // namespace rpem::analysis
