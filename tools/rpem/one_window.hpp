#pragma once
// Whether one window decides an estimate (docs/drive-log.md, "One window decides"): the estimator run again over the
// log with one window's adaptation frozen. Its step is taken out exactly (the estimator is not linearised; the gain's
// Hessian still takes that window's trace, as a frozen estimator's does), and the windows after it adapt from where the
// others left the estimate. A window can move the end by no more than its own
// step (in the linearised recursion the difference is that step times what the later windows leave of it), so only
// windows whose step exceeds the accuracy asked are run again.

#include <cstddef>
#include <optional>
#include <vector>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::tools {

/// One window a parameter adapted on: its index in the log's samples and the change of the estimate it made.
struct AdaptationStep {
  std::size_t index = 0;
  double change = 0.0;  ///< in the parameter's SI unit
};

/// A window whose step, taken out, moves the estimate beyond `tolerance` of it, and where the estimate then ends.
struct DecidingWindow {
  std::size_t index = 0;
  double change = 0.0;   ///< the window's own step
  double without = 0.0;  ///< the estimate at the log's end without that step
};

/// The averaged estimator run again over a whole log with `settings` (the run's machine), `frozen` (if any) the one
/// window whose adaptation is held; parameter 0: ψm's end, 1: R_s' [Wb, Ohm]. The identifiability checks' one pass.
[[nodiscard]] double estimate_at_end(const std::vector<core::AveragedSample>& samples, const core::MachineSi& machine,
                                     const core::EstimatorSettings& settings, std::size_t parameter,
                                     std::optional<std::size_t> frozen = std::nullopt);

/// How many windows are run again at most, the largest steps first: a log with more windows that each move the
/// estimate beyond its accuracy is erratic before any one of them decides it.
inline constexpr std::size_t kMaxWindowsRunAgain = 8;

/// Runs the averaged estimator over `samples` (cfg as the run's) with each candidate of `steps` frozen in turn;
/// `parameter` 0: ψm, 1: R_s. The first window, largest step first, without which the estimate ends more than
/// `tolerance` (relative) from `estimate`; none if no window does.
[[nodiscard]] std::optional<DecidingWindow> window_that_decides(const std::vector<core::AveragedSample>& samples,
                                                                const io::MachineConfig& cfg, std::size_t parameter,
                                                                const std::vector<AdaptationStep>& steps, double estimate,
                                                                double tolerance);

}  // namespace rpem::tools
