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

double Signal::at(double t) noexcept {
  while (active_ + 1 < static_cast<int>(events_.size()) && events_[static_cast<std::size_t>(active_ + 1)].t_s <= t) {
    start_value_ = segment_value(events_[static_cast<std::size_t>(active_ + 1)].t_s);
    ++active_;
  }
  return segment_value(t);
}

}  // namespace rpem::sim
