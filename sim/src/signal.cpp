#include "rpem/sim/signal.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::sim {

double Signal::segment_value(double t) const noexcept {
  if (active_ < 0) return initial_;
  const SignalEvent& e = events_[static_cast<std::size_t>(active_)];
  const double dt = t - e.t_s;
  switch (e.kind) {
    case EventKind::kStep:
      return e.target;
    case EventKind::kRamp:
      return e.duration_s > 0.0 ? start_value_ + (e.target - start_value_) * std::clamp(dt / e.duration_s, 0.0, 1.0)
                                : e.target;
    case EventKind::kThermal:
      return e.duration_s > 0.0 ? e.target + (start_value_ - e.target) * std::exp(-dt / e.duration_s) : e.target;
  }
  return e.target;
}

double Signal::advance(double t) noexcept {
  while (active_ + 1 < static_cast<int>(events_.size()) && events_[static_cast<std::size_t>(active_) + 1].t_s <= t) {
    start_value_ = segment_value(events_[static_cast<std::size_t>(active_) + 1].t_s);
    ++active_;
  }
  const double v = segment_value(t);
  if (active_ + 1 == static_cast<int>(events_.size())) {
    // The last event: a step is final at once, a ramp at its end; a thermal approach never quite is.
    const SignalEvent* e = active_ >= 0 ? &events_[static_cast<std::size_t>(active_)] : nullptr;
    if (!e || e->kind == EventKind::kStep || (e->kind == EventKind::kRamp && t >= e->t_s + e->duration_s)) {
      settled_ = true;
      value_ = v;
    }
  }
  return v;
}

}  // namespace rpem::sim
