#pragma once
// Three Hall sensors as a VESC in Hall mode reads them (`sensors.hall` of a scenario, docs/scenarios.md): six
// states of 60° electrical, each read as the centre of its state (the firmware's Hall table, as its detection
// finds it) below foc_hall_interp_erpm; above it interpolated from the last transition with the speed the
// transitions give (at a transition, the edge between the two states' angles); above foc_sl_erpm the observer's
// angle, taken here as the rotor's (mcpwm_foc.c / foc_math.c, foc_correct_hall; mcconf_default.h). Ideal
// sensors: placed at the states' edges, no debounce, no extra samples.

#include <cstdint>

namespace rpem::sim {

struct HallConfig {
  bool enabled = false;
  double interp_erpm = 250.0;     ///< foc_hall_interp_erpm (MCCONF_FOC_HALL_INTERP_ERPM)
  double observer_erpm = 2000.0;  ///< foc_sl_erpm (MCCONF_FOC_SL_ERPM): the observer's angle above it
};

class HallSensors {
 public:
  HallSensors(const HallConfig& config, double period_s);

  /// The frame angle at this sample, θ plus the Hall reading's error [rad, electrical, as θ: unwrapped]; call
  /// once per period.
  [[nodiscard]] double angle(double theta_el_rad) noexcept;

 private:
  double period_s_;
  double interp_rad_s_, observer_rad_s_;  ///< the two speeds, electrical
  std::int64_t samples_ = 0;
  int state_ = -1;             ///< 0 … 5, the sector ⌊θ/(π/3)⌋ mod 6; −1 before the first sample
  double transition_s_ = 0.0;  ///< when the state last changed
  double interval_s_ = 1e9;    ///< the time between the last two transitions
  double speed_rad_s_ = 0.0;   ///< signed, from the last interval (60° per interval)
  double edge_rad_ = 0.0;      ///< the angle at the last transition, wrapped to [0, 2π)
};

}  // namespace rpem::sim
