#pragma once
// What a drive-log cell may hold (docs/drive-log.md, "Plausibility limits"): the bounds every reader of
// drive data (mapped_log.hpp) holds each quantity to.

#include <string>

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
  Bound time_s{9.0e9, "t is kept in integer nanoseconds, which 64 bits hold up to 9.2e9 s"};
  Bound angle_rad{1.0e9, "beyond 1e9 rad a double resolves the angle no finer than 1.2e-7 rad"};
  Bound speed_rad_s{1.0e6, "10x the fastest electric machines (1e5 rad/s electrical)"};
  Bound voltage_V{1.0e5, "beyond the highest drive DC links (tens of kV)"};
  Bound current_A{1.0e5, "beyond the largest drives' phase currents (tens of kA)"};
  Bound torque_Nm{1.0e7, "beyond the largest machines' torque (MN m)"};
  /// The duty cycle as VESC scales it, 1 at |u_dq| = u_dc/√3 (rotor_frame_rebuild.hpp).
  Bound duty{1.2, "a six-step bridge's fundamental, 2·u_dc/π, is 1.10 x u_dc/√3 (a duty cycle of 1)"};
  double temperature_min_C = -273.15;  ///< absolute zero
  double temperature_max_C = 1000.0;   ///< every winding insulation and magnet has failed long before
  /// A voltage command may be at most this multiple of the same row's u_dc (when u_dc ≥ 1 V): a two-level
  /// inverter applies at most u_dc/2 from the link's midpoint, and 2·u_dc/π as a six-step fundamental.
  double command_per_dc_link = 2.0;
};

}  // namespace rpem::io
