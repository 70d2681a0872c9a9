#pragma once
// Per estimated parameter (ψm, r_s): whether it adapts, whether it is identified, how old its value is,
// whether it is valid and converged, and whether its value now is good — worth persisting; the loop keeps
// the last good value (docs/rpemd.md, "Validity and age").
//
// A parameter *adapts* in a sample when the estimator made its update (StepCode::kAdapted) with the
// parameter's gain row kept by the gain schedule (eq:GainSchedule: ψm where |n| > n_lim,1, r_s where
// |n| < n_lim,2), adaptation of it enabled (estimator.adapt) and not frozen by command — the step flags
// kPsiMActive and kRsActive. Otherwise it is *held* at its last value. Its *age* is the time since the
// last sample in which it adapted, on the loop's clock (−1: never, the value is an initial or a set one).
// It is *identified* after validity.r_s_after_s of adaptation in all (r_s) or validity.psi_m_after_s of
// adaptation without a pause (ψm), until a reset or new initial values; *valid* while identified and
// its age is at most validity.max_hold_s; *converged* when identified and its spread over the last
// validity.convergence_window_s is within validity.convergence_band (a value never identified is still for want
// of adaptation). A sample whose adaptation the estimator took
// back (an averaged window found mixed afterwards, or its chain's unjudged last: docs/derivations.md §13, "Mixed
// windows") is taken back here too: the value is the one before it, and so are its age and identification.
// Real-time safe.

#include <array>
#include <cstdint>

#include "rpem/daemon/daemon_config.hpp"

namespace rpem::daemon {

class ValidityTracker {
 public:
  struct Status {
    bool adapting = false;  ///< in the newest sample
    bool valid = false;
    bool converged = false;
    double age_s = -1.0;
    bool good = false;  ///< valid, converged and adapting: a value worth persisting
  };

  /// `report_rate_Hz`: how often report() is called (it samples the convergence window).
  ValidityTracker(const ValidityConfig& config, double report_rate_Hz) noexcept;

  /// A reload. A changed window restarts the convergence check.
  void reconfigure(const ValidityConfig& config) noexcept;
  /// A persisted value (state file): identified, its last adaptation `age_s` before `now_ns`.
  void seed(int parameter, double age_s, std::int64_t now_ns) noexcept;
  /// A reset or new initial values: nothing identified, nothing adapted, the window empty.
  void restart() noexcept;
  /// No samples (the stream went stale): nothing adapts until the next one.
  void hold() noexcept;
  /// One stepped sample: its step flags and nominal length, at `now_ns`.
  void on_sample(std::uint16_t flags, double dt_s, std::int64_t now_ns) noexcept;
  /// The newest sample's adaptation was taken back (core::Estimate::retracted_previous, or a resynchronize that
  /// retracted): where each parameter stood before that sample, and adapting in none. Once: a second call changes
  /// nothing.
  void retract_last() noexcept;
  /// At each estimate report: adds the value to the parameter's window and says where it stands.
  [[nodiscard]] Status report(int parameter, double value, std::int64_t now_ns) noexcept;

 private:
  static constexpr std::int64_t kNever = INT64_MIN;
  static constexpr int kWindow = 64;
  /// What a sample changes, and retract_last() restores.
  struct Adaptation {
    double adapted_s = 0.0;  ///< toward identification
    bool identified = false;
    std::int64_t last_adapted_ns = kNever;
  };
  struct Parameter {
    Adaptation now, before_last;  ///< before_last: before the newest sample
    bool adapting = false;
    std::array<double, kWindow> window{};
    int count = 0, head = 0;
  };

  [[nodiscard]] bool converged(const Parameter& p) const noexcept;

  ValidityConfig config_;
  double report_rate_Hz_;
  int window_ = 2;
  std::array<Parameter, 2> parameters_{};  ///< indexed by core::kPsiM, core::kRs
};

}  // namespace rpem::daemon
