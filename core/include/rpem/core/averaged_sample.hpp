#pragma once
// One averaged rotor-frame drive sample in SI, as drives beside which rpemd runs report them (VESC's
// COMM_GET_VALUES_SELECTIVE, a signal map over a drive's own frames; docs/sources.md) and as averaged
// drive logs hold them (docs/drive-log.md, "Averaged logs"): the means over the window [t_start, t] of
// the measured rotor-frame current, the drive's rotor-frame voltage, the electrical speed and the DC link.
// A source that samples instead of averaging gives t_start = t.

#include <cstdint>
#include <limits>

#include "rpem/core/types.hpp"

namespace rpem::core {

struct AveragedSample {
  std::int64_t t_start_ns = 0;  ///< window start (== t_ns: an instantaneous sample)
  std::int64_t t_ns = 0;        ///< window end: the host time that closed the window
  Vec2 i_dq_A = Vec2::Zero();   ///< mean measured current, rotor frame
  Vec2 u_dq_V = Vec2::Zero();   ///< mean voltage the drive reports (its command, or its estimate of the applied voltage)
  double omega_el_rad_s = 0.0;  ///< mean electrical speed (as the drive reports it, rebuilt to the window's mean)
  /// The error of omega_el_rad_s its reader states (a tracker's speeds rebuilt to the window's mean, from the change
  /// of acceleration its reads show: core::window_mean_speed_error_rad_s), and the same for the noise of such changes
  /// around the window (core::accel_change_sigma_rad_s2); 0: the window's own mean, as far as the reader knows.
  double omega_el_error_rad_s = 0.0;
  double omega_el_error_noise_rad_s = 0.0;
  /// The larger |speed| the drive reported at the window's two reads (a PLL's speed at each read, from which
  /// omega_el_rad_s is rebuilt): a speed the window passed through, which its mean can hide where the rotor turned back
  /// inside it (docs/derivations.md §13, "A stall's rocking"); NaN: no reads, the speed is the window's own.
  double omega_el_at_reads_max_rad_s = std::numeric_limits<double>::quiet_NaN();
  /// The mean electrical speed the drive's own count of its angle's steps gives over a run of reads centred on this
  /// window (VESC's tachometer: core::grown_count_speed_rad_s, docs/derivations.md §13); NaN: not counted.
  /// Taken instead of omega_el_rad_s where the drive's angle is a staircase (core::window_speed_rad_s).
  double omega_counted_el_rad_s = std::numeric_limits<double>::quiet_NaN();
  double u_dc_V = std::numeric_limits<double>::quiet_NaN();       ///< mean DC link; NaN: not reported
  double t_winding_C = std::numeric_limits<double>::quiet_NaN();  ///< NaN: not reported
  double t_magnet_C = std::numeric_limits<double>::quiet_NaN();   ///< NaN: not reported
  double t_drive_C = std::numeric_limits<double>::quiet_NaN();    ///< power stage; NaN: not reported
  double t_coolant_C = std::numeric_limits<double>::quiet_NaN();  ///< the machine's coolant; NaN: not reported
  bool gap_before = false;                                        ///< windows were lost immediately before this one
};

}  // namespace rpem::core
