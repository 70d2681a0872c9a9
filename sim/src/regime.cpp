#include "rpem/sim/regime.hpp"

#include <stdexcept>
#include <utility>

namespace rpem::sim {

RegimeTimeline::RegimeTimeline(std::vector<RegimeEvent> events) : events_(std::move(events)) {
  for (std::size_t k = 1; k < events_.size(); ++k) {
    if (!(events_[k].t_s > events_[k - 1].t_s))
      throw std::invalid_argument("regime events must be in strictly increasing time");
  }
}

double open_loop_speed_rpm(const RegimeEvent& e, double dt_s) noexcept {
  if (dt_s < e.lock_s) return 0.0;
  if (dt_s < e.lock_s + e.ramp_s) return e.speed_rpm * (dt_s - e.lock_s) / e.ramp_s;
  return e.speed_rpm;
}

RegimeNow RegimeTimeline::at(double t_s) noexcept {
  // The next event's index in size_t: active_ ≥ −1, and −1 widened wraps to 0 once 1 is added.
  while (active_ + 1 < static_cast<int>(events_.size()) && events_[static_cast<std::size_t>(active_) + 1].t_s <= t_s) {
    ++active_;
  }
  RegimeNow now;
  now.event = active_;
  if (active_ < 0) return now;
  const RegimeEvent& e = events_[static_cast<std::size_t>(active_)];
  now.regime = e.regime;
  now.control = e.control;
  now.report = e.report;
  if (e.regime == DriveRegime::kOpenLoop) {
    const double dt = t_s - e.t_s;
    if (dt < e.lock_s + e.ramp_s + e.hold_s) {
      now.open_loop_speed_rpm = open_loop_speed_rpm(e, dt);
    } else {
      now.regime = e.then;  // the sequence is over: back to the observer, or released
    }
  }
  return now;
}

const char* regime_name(DriveRegime r) noexcept {
  switch (r) {
    case DriveRegime::kClosedLoop:
      return "closed_loop";
    case DriveRegime::kOpenLoop:
      return "open_loop";
    case DriveRegime::kBridgeOff:
      return "bridge_off";
  }
  return "?";
}

}  // namespace rpem::sim
