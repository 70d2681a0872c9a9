#pragma once
// A scenario quantity over time: an initial value changed by events — a step, a linear ramp over a
// duration, or a first-order (thermal) approach with a time constant. Evaluated at increasing times.

#include <vector>

namespace rpem::sim {

enum class EventKind { kStep, kRamp, kThermal };

struct SignalEvent {
  double t_s = 0.0;
  EventKind kind = EventKind::kStep;
  double target = 0.0;
  double duration_s = 0.0;  ///< ramp duration, or thermal time constant
};

class Signal {
 public:
  explicit Signal(double initial = 0.0) : initial_(initial), start_value_(initial) {}

  /// Events must be added in time order before the first evaluation.
  void add(const SignalEvent& e) { events_.push_back(e); }

  /// Value at t; t must not decrease between calls.
  [[nodiscard]] double at(double t_s) noexcept;

  [[nodiscard]] double initial() const noexcept { return initial_; }
  [[nodiscard]] const std::vector<SignalEvent>& events() const noexcept { return events_; }

 private:
  [[nodiscard]] double segment_value(double t_s) const noexcept;

  double initial_;
  std::vector<SignalEvent> events_;
  int active_ = -1;          ///< index of the event that shapes the current segment (−1: none yet)
  double start_value_;       ///< value when the active event began
};

}  // namespace rpem::sim
