#pragma once
// What the controller does with the bridge over time (docs/scenarios.md, "Regimes"): the regimes a real
// drive passes through and an emulator that always modulates on the rotor's angle skips. Each follows
// VESC's FOC firmware (vedderb/bldc motor/mcpwm_foc.c):
//   - closed loop: FOC on the rotor's angle (an encoder, or an observer that tracks it), torque or speed
//     control;
//   - open loop: the sensorless start-up of timer_update (and VESC Tool's flux-linkage measurement,
//     conf_general.c conf_general_measure_flux_linkage_openloop): the controller's angle runs open loop —
//     held for `lock_s`, its speed ramped linearly from 0 to the target over `ramp_s`, held at the target for
//     `hold_s` — with the current held on the q axis of that commanded frame; the rotor follows at its load
//     angle. Then the angle returns to the observer (closed loop) or the bridge is released (bridge off);
//   - bridge off: no modulation (stop_pwm_hw): the machine coasts, its current back in the DC link.
// The timeline is built at load (allocates) and read per control period (no allocation).

#include <cstdint>
#include <vector>

namespace rpem::sim {

enum class DriveRegime : std::uint8_t { kClosedLoop, kOpenLoop, kBridgeOff };

/// What a VESC reports as v_d, v_q while its bridge is off (sim/vesc_motor.hpp): the back EMF its phase-
/// voltage sensing tracks (mcpwm_foc.c, the "Motor is not running" branch), or 0 — what the recorded log of
/// issue 23 shows (u_d = u_q = 0 at speed), which the firmware source does not explain.
enum class OffVoltageReport : std::uint8_t { kBackEmf, kZero };

/// Torque or speed control in closed loop; kScenario: the scenario's `control.mode`.
enum class ControlOverride : std::uint8_t { kScenario, kTorque, kSpeed };

struct RegimeEvent {
  double t_s = 0.0;
  DriveRegime regime = DriveRegime::kClosedLoop;
  ControlOverride control = ControlOverride::kScenario;  ///< closed loop (and an open loop's `then`)
  OffVoltageReport report = OffVoltageReport::kBackEmf;  ///< bridge off (and an open loop's `then`)
  // Open loop:
  double current_A = 0.0;                       ///< |i_q| held in the commanded frame (sign: the direction of speed_rpm)
  double speed_rpm = 0.0;                       ///< target speed, mechanical, signed
  double lock_s = 0.0;                          ///< foc_sl_openloop_time_lock
  double ramp_s = 0.0;                          ///< foc_sl_openloop_time_ramp
  double hold_s = 0.05;                         ///< foc_sl_openloop_time (mcconf_default.h: 0.05 s)
  DriveRegime then = DriveRegime::kClosedLoop;  ///< after the hold: kClosedLoop or kBridgeOff
};

/// The regime at one instant.
struct RegimeNow {
  DriveRegime regime = DriveRegime::kClosedLoop;
  ControlOverride control = ControlOverride::kScenario;
  OffVoltageReport report = OffVoltageReport::kBackEmf;
  int event = -1;                    ///< index of the event in force (−1: none yet)
  double open_loop_speed_rpm = 0.0;  ///< open loop: the commanded speed now (mechanical)
};

class RegimeTimeline {
 public:
  RegimeTimeline() = default;
  /// Events in strictly increasing time (the scenario reader checks it).
  explicit RegimeTimeline(std::vector<RegimeEvent> events);

  /// The regime at t; t must not decrease between calls.
  [[nodiscard]] RegimeNow at(double t_s) noexcept;
  [[nodiscard]] const std::vector<RegimeEvent>& events() const noexcept { return events_; }
  [[nodiscard]] bool empty() const noexcept { return events_.empty(); }

 private:
  std::vector<RegimeEvent> events_;
  int active_ = -1;
};

/// An open-loop sequence's commanded speed (mechanical rpm) `dt_s` after its start: 0 while locked, a
/// linear ramp to the target, then the target (mcpwm_foc.c, timer_update: openloop_rpm from utils_map over
/// [t_lock, t_lock + t_ramp]).
[[nodiscard]] double open_loop_speed_rpm(const RegimeEvent& e, double dt_s) noexcept;

[[nodiscard]] const char* regime_name(DriveRegime r) noexcept;

}  // namespace rpem::sim
