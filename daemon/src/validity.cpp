#include "rpem/daemon/validity.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/clock.hpp"
#include "rpem/core/estimator.hpp"

namespace rpem::daemon {

ValidityTracker::ValidityTracker(const ValidityConfig& config, double report_rate_Hz) noexcept
    : report_rate_Hz_(report_rate_Hz) {
  reconfigure(config);
}

void ValidityTracker::reconfigure(const ValidityConfig& config) noexcept {
  config_ = config;
  const int window = std::clamp(static_cast<int>(config.convergence_window_s * report_rate_Hz_), 2, kWindow);
  if (window != window_) {
    window_ = window;
    for (Parameter& p : parameters_) p.count = p.head = 0;
  }
}

void ValidityTracker::seed(int parameter, double age_s, std::int64_t now_ns) noexcept {
  Parameter& p = parameters_[static_cast<std::size_t>(parameter)];
  p.now.identified = true;
  p.now.last_adapted_ns = now_ns - static_cast<std::int64_t>(std::max(0.0, age_s) * 1e9);
  p.before_last = p.now;  // no retraction reaches behind a seed
}

void ValidityTracker::restart() noexcept {
  for (Parameter& p : parameters_) p = Parameter{};
}

void ValidityTracker::hold() noexcept {
  parameters_[core::kPsiM].now.adapted_s = 0.0;  // a pause
  for (Parameter& p : parameters_) {
    p.adapting = false;
    p.before_last = p.now;  // no retraction reaches behind a pause
  }
}

void ValidityTracker::on_sample(std::uint16_t flags, double dt_s, std::int64_t now_ns) noexcept {
  const bool active[2] = {(flags & core::step_flag::kPsiMActive) != 0, (flags & core::step_flag::kRsActive) != 0};
  const double after_s[2] = {config_.psi_m_after_s, config_.r_s_after_s};
  for (int j = 0; j < 2; ++j) {
    Parameter& p = parameters_[static_cast<std::size_t>(j)];
    p.before_last = p.now;
    p.adapting = active[j];
    Adaptation& a = p.now;
    if (active[j]) {
      a.adapted_s += dt_s;
      a.last_adapted_ns = now_ns;
    } else if (j == core::kPsiM) {
      a.adapted_s = 0.0;  // ψm is identified by adaptation without a pause
    }
    if (a.adapted_s >= after_s[j]) a.identified = true;
  }
}

void ValidityTracker::retract_last() noexcept {
  for (Parameter& p : parameters_) {
    p.now = p.before_last;
    p.adapting = false;
  }
}

bool ValidityTracker::converged(const Parameter& p) const noexcept {
  // A value never identified is still for want of adaptation, not because it has converged.
  if (!p.now.identified || p.count < window_) return false;
  double lo = p.window[0], hi = p.window[0];
  for (int k = 1; k < window_; ++k) {
    lo = std::min(lo, p.window[static_cast<std::size_t>(k)]);
    hi = std::max(hi, p.window[static_cast<std::size_t>(k)]);
  }
  return hi - lo <= config_.convergence_band * std::abs(hi);
}

ValidityTracker::Status ValidityTracker::report(int parameter, double value, std::int64_t now_ns) noexcept {
  Parameter& p = parameters_[static_cast<std::size_t>(parameter)];
  p.window[static_cast<std::size_t>(p.head)] = value;
  p.head = (p.head + 1) % window_;
  p.count = std::min(p.count + 1, window_);
  Status s;
  s.adapting = p.adapting;
  s.converged = converged(p);
  if (p.now.last_adapted_ns != kNever) {
    s.age_s = core::to_seconds(std::max<std::int64_t>(0, now_ns - p.now.last_adapted_ns));
  }
  s.valid = p.now.identified && s.age_s >= 0.0 && s.age_s <= config_.max_hold_s;
  s.good = s.valid && s.converged && s.adapting;
  return s;
}

}  // namespace rpem::daemon
