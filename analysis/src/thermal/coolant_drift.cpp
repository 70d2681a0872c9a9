#include "rpem/analysis/thermal/coolant_drift.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace rpem::analysis {
namespace {

/// D(s) at a lag of `lag` steps over every session's read steps: the mean squared move and the mean time it took.
struct LagMoment {
  double sum_sq_K2 = 0.0, sum_fourth_K4 = 0.0, sum_s = 0.0;
  std::size_t pairs = 0, lag = 1;
  [[nodiscard]] double d_K2() const { return sum_sq_K2 / static_cast<double>(pairs); }
  /// D's standard error: the moves' Var(Δ²) over the independent moves among them (pairs/lag: moves at a lag of
  /// `lag` steps overlap, and a walk's overlapping moves are correlated).
  [[nodiscard]] double standard_error_K2() const {
    const double n = static_cast<double>(pairs), d = d_K2();
    const double var = std::max(0.0, sum_fourth_K4 / n - d * d);
    return std::sqrt(var * static_cast<double>(lag) / n);
  }
};

/// A move counts where it exceeds D_floor by this many of their standard errors: noise alone gets past it at one
/// lag in 44 (one-sided normal).
constexpr double kSignificance_sigma = 2.0;

}  // namespace

CoolantDrift coolant_drift(const ThermalRecord& r, std::size_t training) {
  training = std::min(training, r.steps.size());
  std::size_t longest = 0;  // the longest session's training steps
  for (std::size_t j = 0; j < r.session_first_step.size(); ++j) {
    const std::size_t first = r.session_first_step[j], end = std::min(r.session_end(j), training);
    if (end > first) longest = std::max(longest, end - first);
  }
  std::vector<LagMoment> moments;
  // Lags up to a 32nd of the longest session: each D(s) a mean over at least 32 independent moves (its relative
  // standard error √(2/32) = 0.25 for a walk), so that the maximum over lags is not one move's chance.
  constexpr std::size_t kIndependentMoves = 32;
  for (std::size_t lag = 1; kIndependentMoves * lag <= longest; lag *= 2) {
    LagMoment m;
    m.lag = lag;
    for (std::size_t j = 0; j < r.session_first_step.size(); ++j) {
      if (!r.session_has_coolant(j)) continue;
      const std::size_t first = r.session_first_step[j], end = std::min(r.session_end(j), training);
      for (std::size_t k = first; k + lag < end; ++k) {
        const core::ThermalStepData &a = r.steps[k], &b = r.steps[k + lag];
        if (!a.coolant_read || !b.coolant_read) continue;
        const double move_K = b.load.coolant_C - a.load.coolant_C;
        m.sum_sq_K2 += move_K * move_K;
        m.sum_fourth_K4 += move_K * move_K * move_K * move_K;
        m.sum_s += r.t_s[k + lag] - r.t_s[k];
        ++m.pairs;
      }
    }
    if (m.pairs > 0 && m.sum_s > 0.0) moments.push_back(m);
  }
  CoolantDrift out;
  out.lags = static_cast<int>(moments.size());
  if (moments.size() < 2) return out;  // one lag cannot tell the readings' noise from a move
  const LagMoment* floor = &moments.front();
  for (const LagMoment& m : moments) floor = m.d_K2() < floor->d_K2() ? &m : floor;
  out.floor_K2 = floor->d_K2();
  out.shortest_lag_s = moments.front().sum_s / static_cast<double>(moments.front().pairs);
  out.longest_lag_s = moments.back().sum_s / static_cast<double>(moments.back().pairs);
  for (const LagMoment& m : moments) {
    const double n = static_cast<double>(m.pairs), lag_s = m.sum_s / n;
    const double error_K2 = std::hypot(m.standard_error_K2(), floor->standard_error_K2());
    const double q = (m.d_K2() - out.floor_K2 - kSignificance_sigma * error_K2) / lag_s;
    if (q > out.q_K2_per_s) {
      out.q_K2_per_s = q;
      out.at_lag_s = lag_s;
    }
  }
  return out;
}

std::string coolant_drift_sentence(const CoolantDrift& d) {
  char text[640];
  if (d.lags < 2) {
    std::snprintf(text, sizeof text,
                  "Coolant drift: the training part has no coolant readings over two lags or more, so q_c is 0 and a "
                  "held coolant reading counts as exact; where a drive's coolant sensor may go silent, set "
                  "thermal.coolant_drift_K2_per_s (eq. 14.29).");
  } else if (!(d.q_K2_per_s > 0.0)) {
    std::snprintf(text, sizeof text,
                  "Coolant drift: the coolant readings move no more than their floor of %.3g K² at any lag from %.3g "
                  "to %.3g s, so q_c is 0 and a held coolant reading counts as exact (eq. 14.29b).",
                  d.floor_K2, d.shortest_lag_s, d.longest_lag_s);
  } else {
    constexpr double kTenMinutes_s = 600.0;
    std::snprintf(text, sizeof text,
                  "Coolant drift: q_c = %.3g K²/s, the smallest random walk that bounds the coolant readings' moves "
                  "beyond their floor of %.3g K² at every lag from %.3g to %.3g s (set at %.3g s; eq. 14.29b). A "
                  "coolant sensor that goes silent widens the band from there: the coolant's σ is %.2g K after ten "
                  "minutes unread.",
                  d.q_K2_per_s, d.floor_K2, d.shortest_lag_s, d.longest_lag_s, d.at_lag_s,
                  std::sqrt(d.q_K2_per_s * kTenMinutes_s));
  }
  return text;
}

}  // namespace rpem::analysis
