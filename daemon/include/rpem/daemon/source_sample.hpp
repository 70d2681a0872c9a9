#pragma once
// What a source hands the estimator loop (docs/rpemd.md, "Sources"): a phase sample at the drive's
// control rate (core::DriveSample: the native CAN source, the simulator, signal maps of phase
// quantities and angle) or an averaged rotor-frame sample over a window between two host timestamps
// (core::AveragedSample: VESC, signal maps of rotor-frame quantities). A source produces one kind, which
// its configuration names (SourceCatalogue::sample_kind); the loop runs the estimator for that kind.

#include <cstdint>
#include <variant>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/drive_sample.hpp"

namespace rpem::daemon {

/// The alternative a SourceSample holds: the numbers are the variant's indices.
enum class SampleKind : std::uint8_t { kPhase = 0, kAveraged = 1 };

using SourceSample = std::variant<core::DriveSample, core::AveragedSample>;

/// How far apart a source's samples come where the source itself sets that (a poller: docs/rpemd.md,
/// `stale_timeout_s`); both 0 where the drive pushes them at a rate rpemd is not told.
struct SampleSpacing {
  double normal_s = 0.0;    ///< the longest interval between two samples in normal operation
  double one_lost_s = 0.0;  ///< the same where one reply in between is lost
};

[[nodiscard]] inline SampleKind kind_of(const SourceSample& s) noexcept { return static_cast<SampleKind>(s.index()); }
[[nodiscard]] inline const char* to_string(SampleKind k) noexcept { return k == SampleKind::kPhase ? "phase" : "averaged"; }

}  // namespace rpem::daemon
