#pragma once
// What the user and the VESC's app do to the motor, one segment after the other (README "Scenario"):
// the commands the firmware receives every millisecond, as an app (ADC, PPM, VESC Tool's keyboard control)
// or VESC Tool's motor detection sends them.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace indep::vesc {

enum class SegmentKind {
  off,               // release the motor: the firmware stops modulating (bridge off, freewheel)
  current,           // current control at current_A (ramped from the previous command over ramp_s)
  coast,             // current control at 0 A with the off-delay covering the segment: modulating at i = 0
  brake,             // regenerative current |current_A| against the direction the motor turns at its start
  flux_measurement,  // VESC Tool's flux-linkage measurement: open-loop current, ERPM ramp, then bridge off
};

struct Segment {
  SegmentKind kind = SegmentKind::off;
  double duration_s = 1.0;  // the longest it lasts (a flux measurement lasts as its sequence does)
  double current_A = 0.0;
  double ramp_s = 0.0;         // current: linear from the previous command
  double until_erpm = 0.0;     // current, brake: ends early once |ERPM| reaches (current) or falls below (brake) this
  double erpm_per_s = 1800.0;  // flux_measurement: the open-loop ramp rate (conf_general_detect_apply_all)
  double external_Nm = 0.0;    // a torque on the shaft during the segment (a hand turning the rotor, a slope)
  double friction_Nm = 0.0;    // bearing-like friction added during the segment (a load to start against)
  double viscous_Nm_s = 0.0;   // a load proportional to the shaft speed added during the segment (an eddy-current
                               // brake, a dynamometer): with a constant current it sets a steady speed
};

const char* to_string(SegmentKind k);

/// The built-in scenario drawn from the seed (README "Scenario"): standstill, a flux measurement, then episodes
/// of open-loop start-ups, hard accelerations, cruising, freewheeling, minutes of zero-current coasting and
/// braking, forwards and backwards, until `duration_s`. Currents scale with `l_current_max_A`, ERPM targets
/// with `rated_erpm`. Before a start from standstill a hand turns the rotor slowly with `creep_torque_Nm` while
/// the bridge is off: that back EMF hides in the phase voltages' resolution and the observer loses the angle.
/// Starts are made against a load of 30–70 % of the torque the start current gives (`torque_per_A_Nm` per
/// ampere): the rotor stays slow long enough for the firmware's open-loop start-up.
std::vector<Segment> builtin_scenario(double duration_s, double l_current_max_A, double rated_erpm, double creep_torque_Nm,
                                      double torque_per_A_Nm, std::uint64_t seed);

/// The built-in Hall ride (README "Hall mode"), drawn from the seed: a Hall drive starts in closed loop, so no
/// open-loop start-ups: standstill, then episodes (forwards, forwards, backwards) of a holding current against a
/// brake, crawling well below foc_hall_interp_erpm, a speed in the interpolated range, one above foc_sl_erpm, each
/// set by a current against a viscous load (sized on the configured machine: `torque_per_A_Nm`, the true machine's
/// ψm moves the speed with it), then zero current with the bridge on while the shaft runs down through every
/// range, and the bridge off.
std::vector<Segment> builtin_hall_scenario(double duration_s, double l_current_max_A, double torque_per_A_Nm, int pole_pairs,
                                           std::uint64_t seed);

/// A scenario file: CSV with header
/// `kind,duration_s,current_A[,ramp_s,until_erpm,erpm_per_s,external_Nm,friction_Nm,viscous_Nm_s]`.
struct ScenarioError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Reads a scenario file; throws ScenarioError naming `file:line: reason`.
std::vector<Segment> read_scenario_csv(const std::string& path);

}  // namespace indep::vesc
