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
// The floor can be unknown: it rests only on samples whose neighbours within the block are replayed too —
// the samples of a transient log, and in a steady-state log the rows at a repeated operating point (rows in
// transition between operating points, and idle ones, are not replayed: log_data.cpp). A log of rows that
// each sit at another operating point (a bench's sparse samples of a dynamic profile) has too few such
// triples; the floor is then not measured (std::nullopt, with the reason), never 0.
//
// The verdict is "explained" when the final held-out residual is at most kExplainedRatio times the
// floor; otherwise "unexplained", with where the residual lives and what would explain it; "undetermined"
// when the floor is unknown (whether the residual is noise cannot be told).

#include <optional>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/replay.hpp"
#include "rpem/analysis/diagnose/residual_statistics.hpp"

namespace rpem::analysis {

/// A residual up to this many times the noise floor counts as explained (docs/diagnose.md).
inline constexpr double kExplainedRatio = 1.5;

/// Second differences the floor needs. From n of them (one run, both axes) the estimate's 2.5 % quantile
/// lies at 0.67 of the true floor for n = 20 (0.59 for n = 10; Monte Carlo over white noise,
/// `NoiseFloor.TwentySecondDifferencesMeasureItWellEnoughForTheVerdict`): with at least 20, a residual that
/// is the sensors' noise stays within kExplainedRatio = 1.5 ≈ 1/0.67 of the estimate with 97.5 % probability.
inline constexpr std::size_t kMinNoiseDifferences = 20;

/// The noise floor of a replay's residual (see above).
struct NoiseFloor {
  std::optional<double> value_A;  ///< empty: cannot be measured on this log
  std::size_t differences = 0;    ///< second differences it rests on (per axis)
  std::string unknown_reason;     ///< why it is unknown (empty when measured)

  /// The σ the fits scale by: the floor, or 0 where it is unknown — no excited constant is then held back by
  /// the excitation test, and no model change counts as below the noise (diagnosis.cpp).
  [[nodiscard]] double for_fits_A() const noexcept { return value_A.value_or(0.0); }
};

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
  /// The noise floor (see above); unknown, with the reason, if too few differences.
  [[nodiscard]] NoiseFloor noise_floor(const LogData& log) &&;

 private:
  struct Last {
    std::size_t k = static_cast<std::size_t>(-1);
    core::Vec2 r = core::Vec2::Zero();
    bool valid = false;
  };
  Last last_, previous_;
  std::vector<double> d2_, q2_;
  std::size_t valid_ = 0;  ///< samples with a prediction (the reason an unknown floor gives)
};

/// The noise floor of a whole replay's residual (tests and small logs; a diagnosis streams).
[[nodiscard]] NoiseFloor measure_noise_floor(const LogData& log, const ReplayOutput& replay);

enum class VerdictKind { kExplained, kUnexplained, kUndetermined };

[[nodiscard]] const char* to_string(VerdictKind k) noexcept;

struct Verdict {
  VerdictKind kind = VerdictKind::kUndetermined;
  std::optional<double> noise_floor_A;  ///< empty: unknown (kUndetermined)
  std::optional<double> ratio;          ///< final held-out residual RMS / noise floor; empty where the floor is unknown
  /// Unexplained or undetermined: where the residual lives (operating region, angle harmonics, correlations)
  /// and what kind of effect or data would explain it; undetermined: first why the floor is unknown.
  std::vector<std::string> findings;

  [[nodiscard]] bool explained() const noexcept { return kind == VerdictKind::kExplained; }
};

/// `statistics`' "after" side is the final model's residual.
[[nodiscard]] Verdict verdict(double final_heldout_rms_A, const NoiseFloor& floor, const ResidualStatistics& statistics);

}  // namespace rpem::analysis
