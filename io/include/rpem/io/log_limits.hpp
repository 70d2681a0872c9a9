#pragma once
// What a drive-log cell may hold (docs/drive-log.md, "Plausibility limits"): the bounds every reader of
// drive data (mapped_log.hpp) holds each quantity to — core::PlausibleMagnitudes' figures, with where each comes
// from for the error message.

#include <string>

#include "rpem/core/plausibility.hpp"

namespace rpem::io {

/// A magnitude no drive produces, and where the figure comes from (quoted in the error message).
struct Bound {
  double max_abs = 0.0;
  std::string why;
};

/// What a drive-log cell may hold (docs/drive-log.md, "Plausibility limits"). The defaults are absolute:
/// no drive, whatever its machine, produces a value beyond them. A tool that knows the machine narrows
/// them to a multiple of its name plate (io::machine_limits). A cell beyond its bound, like a NaN, stops
/// the reader with file:line:column.
struct DriveLogLimits {
  static constexpr core::PlausibleMagnitudes kAbsolute{};
  Bound time_s{kAbsolute.time_s, "t is kept in integer nanoseconds, which 64 bits hold up to 9.2e9 s"};
  Bound angle_rad{kAbsolute.angle_rad, "beyond 1e9 rad a double resolves the angle no finer than 1.2e-7 rad"};
  Bound speed_rad_s{kAbsolute.speed_rad_s, "10x the fastest electric machines (1e5 rad/s electrical)"};
  Bound voltage_V{kAbsolute.voltage_V, "beyond the highest drive DC links (tens of kV)"};
  /// u_dc: the inverter's, never narrowed to a machine (core::PlausibleMagnitudes::dc_link_V).
  Bound dc_link_V{kAbsolute.dc_link_V, "beyond the highest drive DC links (tens of kV)"};
  Bound current_A{kAbsolute.current_A, "beyond the largest drives' phase currents (tens of kA)"};
  Bound torque_Nm{kAbsolute.torque_Nm, "beyond the largest machines' torque (MN m)"};
  /// The duty cycle as VESC scales it, 1 at |u_dq| = u_dc/√3 (rotor_frame_rebuild.hpp).
  Bound duty{1.2, "a six-step bridge's fundamental, 2·u_dc/π, is 1.10 x u_dc/√3 (a duty cycle of 1)"};
  double temperature_min_C = kAbsolute.temperature_min_C;
  double temperature_max_C = kAbsolute.temperature_max_C;
  /// A voltage command may be at most this multiple of the same row's u_dc (when u_dc ≥ 1 V): a two-level
  /// inverter applies at most u_dc/2 from the link's midpoint, and 2·u_dc/π as a six-step fundamental.
  double command_per_dc_link = 2.0;
  /// The drive's control period T_c (estimator.averaged.control_period_s; 0: not known, not checked). An averaged
  /// window's means hold whole control cycles, so a log whose median window is shorter than half of one (its stamps'
  /// rounding allowed) has its time in
  /// another unit than it says (a map's `unit:`) or the configuration has another drive's T_c.
  double control_period_s = 0.0;
};

}  // namespace rpem::io
