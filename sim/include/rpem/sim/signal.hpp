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
  void add(const SignalEvent& e) {
    events_.push_back(e);
    settled_ = false;
  }

  /// Value at t; t must not decrease between calls. A signal past its last change is a stored value
  /// (most of a scenario's signals, every control period).
  [[nodiscard]] double at(double t_s) noexcept { return settled_ ? value_ : advance(t_s); }

  [[nodiscard]] double initial() const noexcept { return initial_; }
  [[nodiscard]] const std::vector<SignalEvent>& events() const noexcept { return events_; }

 private:
  [[nodiscard]] double segment_value(double t_s) const noexcept;
  [[nodiscard]] double advance(double t_s) noexcept;

  double initial_;
  std::vector<SignalEvent> events_;
  int active_ = -1;          ///< index of the event that shapes the current segment (−1: none yet)
  double start_value_;       ///< value when the active event began
  bool settled_ = true;      ///< no event ahead and the last one has reached its final value
  double value_ = initial_;  ///< the value once settled
};

}  // namespace rpem::sim
