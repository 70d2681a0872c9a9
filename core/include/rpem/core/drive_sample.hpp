#pragma once
// One drive measurement in SI, as logged by a drive or received from the CAN bus
// (docs/drive-log.md): currents, angle and speed sampled at t, and the voltage command issued at t,
// held constant in the stator frame until the next sample; and the drive's temperature sensors where a reading
// came with the sample (a sensor reports at its own, slower rate: NaN on the samples between its readings).

#include <cstdint>
#include <limits>

#include "rpem/core/types.hpp"

namespace rpem::core {

/// Frame of a three-element quantity: phases (a, b, c), stator (α, β, –) or rotor (d, q, –).
enum class Frame : std::uint8_t { kAbc = 0, kAlphaBeta = 1, kDq = 2 };

struct DriveSample {
  std::int64_t t_ns = 0;
  double theta_el_rad = 0.0;
  double omega_el_rad_s = 0.0;
  double u_dc_V = 0.0;
  Frame voltage_frame = Frame::kAbc;
  Vec3 u_V = Vec3::Zero();  ///< voltage command in voltage_frame
  Frame current_frame = Frame::kAbc;
  Vec3 i_A = Vec3::Zero();  ///< measured current in current_frame
  bool gap_before = false;  ///< samples were lost immediately before this one
  std::int64_t rx_ns = 0;   ///< when the transport received it (CLOCK_REALTIME, kernel stamp); 0: unknown
  double t_winding_C = std::numeric_limits<double>::quiet_NaN();  ///< the winding's sensor; NaN: no reading
  double t_coolant_C = std::numeric_limits<double>::quiet_NaN();  ///< the machine's coolant; NaN: no reading
};

}  // namespace rpem::core
