#pragma once
// What a drive's measurements may hold (docs/drive-log.md, "Plausibility limits"): the magnitudes no drive produces,
// and the narrower ones of a configured machine, a multiple of its rating. The log readers hold every cell to them
// (io/log_limits.hpp, which quotes where each figure comes from) and rpemd's loop every sample a live source
// delivers (daemon/loop_thread.cpp): a value beyond them is a wrong unit, a wrong name plate or a corrupted read,
// and is never estimated on.

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/drive_sample.hpp"
#include "rpem/core/per_unit.hpp"

namespace rpem::core {

/// Largest magnitudes, SI. The defaults are absolute: no drive, whatever its machine, produces a value beyond them.
struct PlausibleMagnitudes {
  double time_s = 9.0e9;       ///< integer nanoseconds in 64 bits hold up to 9.2e9 s
  double angle_rad = 1.0e9;    ///< beyond it a double resolves an angle no finer than 1.2e-7 rad
  double speed_rad_s = 1.0e6;  ///< 10 x the fastest electric machines' electrical speed (1e5 rad/s)
  double voltage_V = 1.0e5;    ///< beyond the highest drive DC links (tens of kV)
  /// The DC link is the inverter's, not the machine's: held to the absolute figure only, never narrowed to a
  /// machine (a machine rated for a 48 V link may run on a 560 V one, as the AX8000 rig's AM8141 does).
  double dc_link_V = 1.0e5;
  double current_A = 1.0e5;            ///< beyond the largest drives' phase currents (tens of kA)
  double torque_Nm = 1.0e7;            ///< beyond the largest machines' torque (MN m)
  double temperature_min_C = -273.15;  ///< absolute zero
  double temperature_max_C = 1000.0;   ///< every winding insulation and magnet has failed long before
};

/// A machine's currents, voltages and electrical speed beyond this multiple of its per-unit base (the rated peak
/// phase current and voltage, the rated electrical speed; docs/per-unit.md) mean a wrong unit or name plate: drives
/// overload by 1.5–3 x and weaken the field to about 4 x base speed.
inline constexpr double kRatedMultipleLimit = 10.0;

/// The absolute magnitudes, with current, voltage (the phase voltages, not the DC link) and speed narrowed to
/// kRatedMultipleLimit x the machine's base where that is narrower.
[[nodiscard]] PlausibleMagnitudes machine_plausible(const RatedData& rated) noexcept;

/// Whether every value of the sample is within the magnitudes (|x| ≤ its limit; a temperature between its two).
/// NaN passes: whether a value may be absent is the estimator's question (StepCode::kRejectedNonFinite), not this.
[[nodiscard]] bool within(const DriveSample& s, const PlausibleMagnitudes& m) noexcept;
[[nodiscard]] bool within(const AveragedSample& s, const PlausibleMagnitudes& m) noexcept;

}  // namespace rpem::core
