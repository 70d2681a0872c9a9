#pragma once
// What an estimator run, or a diagnosis's replay, did with its samples: how many fell in each regime
// (core/regime.hpp), resynchronised or were skipped as outliers; a summary line for the user, and — where
// more than a tenth of the samples adapted nothing — which rule did it and which configuration key changes
// it (docs/derivations.md §13). `rpem estimate` prints them on stderr; `rpem diagnose` writes the same
// sentences into its report.

#include <cstdint>
#include <string>
#include <vector>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/regime.hpp"

namespace rpem::io {

struct SampleCounts {
  core::RegimeCounts regimes;
  std::uint64_t samples = 0;
  /// StepCode kSynchronized and kPredictorDiverged: a chain started over, nothing adapted — not the first sample's
  /// synchronisation after the estimator was made or reset (a start, not a restart).
  std::uint64_t resyncs = 0;
  std::uint64_t outliers = 0;  ///< StepCode kOutlier
  bool averaged = false;       ///< an averaged log (its resyncs are gaps and late windows)

  /// Counts one estimator output.
  void add(const core::Estimate& e) noexcept;
  /// The estimator was reset (a session's start): its next synchronisation is a start.
  void start_session() noexcept { started_ = false; }

 private:
  bool started_ = false;  ///< a sample was counted since the estimator was made or reset
};

/// "regimes: excites_both 12, excites_psi_m 8012, …, resyncs 3, outliers 0".
[[nodiscard]] std::string regime_summary(const SampleCounts& c);

/// Where samples excited R_s only on the assumed frame: how many, why it matters and which key settles it (the tools
/// print it as a note). Empty where none did (a stated angle_source, or nothing that depended on it).
[[nodiscard]] std::string assumed_frame_note(const SampleCounts& c);

/// The share of the samples above which a rule is explained.
inline constexpr double kExplainedShare = 0.10;

/// One sentence per rule that took more than `share` of the samples: how many, what the rule is, which
/// configuration keys change it. Empty when none did.
[[nodiscard]] std::vector<std::string> exclusion_explanations(const SampleCounts& c, double share = kExplainedShare);

}  // namespace rpem::io
