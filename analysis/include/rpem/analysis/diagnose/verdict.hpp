#pragma once
// Whether the diagnosis explains the log (docs/diagnose.md, "Noise floor and verdict"). The noise floor
// is estimated from the data itself: a model's residual is the sensors' noise plus the model's error,
// and the error is smooth at the sampling rate (it follows the machine's currents, speeds and
// temperatures) while the noise is white. Second differences within each block, e_k = r_{k+1} − 2·r_k +
// r_{k−1}, remove the smooth part (a sinusoid of frequency f keeps (2·sin(π·f·T))² of its amplitude: 4 %
// at a 270 Hz 6th harmonic sampled at 8 kHz) and multiply white noise's variance by 1 + 4 + 1 = 6; the
// median of e², divided by 6 and by 0.4549 (the median of χ²₁), gives each axis' variance robustly
// against the few samples where the error is not smooth (steps, gaps). noise_floor_A = √(σ_d² + σ_q²),
// the RMS of the residual vector's white part, comparable with the residual RMS.
//
// The verdict is "explained" when the final held-out residual is at most kExplainedRatio times the
// floor; otherwise "unexplained", with where the residual lives and what would explain it.

#include <string>
#include <vector>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/replay.hpp"
#include "rpem/analysis/diagnose/residual_statistics.hpp"

namespace rpem::analysis {

/// A residual up to this many times the noise floor counts as explained (docs/diagnose.md).
inline constexpr double kExplainedRatio = 1.5;

/// The squared second differences of a replay's residual, per axis, as a replay streams through the
/// blocks (what the floor's medians are taken of: their order does not matter).
class SecondDifferences {
 public:
  /// Sample k of a block, in order (the samples a replay visits); a new block starts with start().
  void add(const LogData& log, std::size_t k, const ModelSample& m);
  void start() noexcept { last_ = previous_ = Last{}; }
  /// Another block's differences.
  void append(const SecondDifferences& other);
  [[nodiscard]] std::size_t size() const noexcept { return d2_.size(); }
  /// The noise floor [A] (see above); 0 if too few differences.
  [[nodiscard]] double noise_floor_A() &&;

 private:
  struct Last {
    std::size_t k = static_cast<std::size_t>(-1);
    core::Vec2 r = core::Vec2::Zero();
    bool valid = false;
  };
  Last last_, previous_;
  std::vector<double> d2_, q2_;
};

/// The noise floor of a whole replay's residual [A] (tests); 0 if too few consecutive valid samples.
[[nodiscard]] double noise_floor_A(const LogData& log, const ReplayOutput& replay);

struct Verdict {
  bool explained = false;
  double noise_floor_A = 0.0;
  double ratio = 0.0;  ///< final held-out residual RMS / noise floor
  /// Unexplained: where the residual lives (operating region, angle harmonics, correlations) and what
  /// kind of effect or data would explain it.
  std::vector<std::string> findings;
};

/// `statistics`' "after" side is the final model's residual.
[[nodiscard]] Verdict verdict(double final_heldout_rms_A, double noise_floor_A, const ResidualStatistics& statistics);

}  // namespace rpem::analysis
