#include "rpem/sim/hall_sensors.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/frames.hpp"

namespace rpem::sim {
namespace {

constexpr double kSector = core::kPi / 3.0;
constexpr double kErpmToRadS = 2.0 * core::kPi / 60.0;

}  // namespace

HallSensors::HallSensors(const HallConfig& config, double period_s)
    : period_s_(period_s),
      interp_rad_s_(config.interp_erpm * kErpmToRadS),
      observer_rad_s_(config.observer_erpm * kErpmToRadS) {}

double HallSensors::angle(double theta_el_rad) noexcept {
  const double t = static_cast<double>(samples_++) * period_s_;
  const double wrapped = theta_el_rad - 2.0 * core::kPi * std::floor(theta_el_rad / (2.0 * core::kPi));
  const int state = std::min(5, static_cast<int>(wrapped / kSector));
  if (state_ >= 0 && state != state_) {
    // One step forward or back; a jump of more (a rotor faster than a state per sample) is read as forward.
    const int step = (state - state_ + 6) % 6 == 5 ? -1 : 1;
    interval_s_ = t - transition_s_;
    transition_s_ = t;
    speed_rad_s_ = step * kSector / std::max(interval_s_, period_s_);
    edge_rad_ = (step > 0 ? state : state_) * kSector;  // the boundary just crossed
  }
  state_ = state;
  // The firmware's speed: 60° over the longer of the last interval and the time since (it decays at standstill).
  const double since = t - transition_s_;
  const double speed_abs = kSector / std::max({interval_s_, since, period_s_});
  double reading = 0.0;
  if (speed_abs >= observer_rad_s_) return theta_el_rad;  // the observer's angle
  if (speed_abs < interp_rad_s_) {
    reading = (state + 0.5) * kSector;  // the state's angle from the table
  } else {
    // Interpolated from the last edge with the transitions' speed, held within the present state.
    const double centre = (state + 0.5) * kSector;
    const double ahead = core::wrap_angle(edge_rad_ + speed_rad_s_ * since - centre);
    reading = centre + std::clamp(ahead, -0.5 * kSector, 0.5 * kSector);
  }
  return theta_el_rad + core::wrap_angle(reading - wrapped);
}

}  // namespace rpem::sim
