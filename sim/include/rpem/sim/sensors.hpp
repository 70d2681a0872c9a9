#pragma once
// What the drive measures: phase currents (gain error, offset, noise, ADC quantisation), the
// encoder angle (resolution, misalignment) or a VESC's Hall sensors' reading, a speed from the encoder angle over a window, and the
// DC-link voltage (noise, quantisation). The sensor errors are the effects rpem diagnose must find.

#include <cstdint>
#include <vector>

#include "rpem/core/types.hpp"
#include "rpem/sim/gaussian.hpp"
#include "rpem/sim/hall_sensors.hpp"

namespace rpem::sim {

struct SensorConfig {
  double current_noise_A = 0.0;  ///< standard deviation of white noise per phase
  double current_lsb_A = 0.0;    ///< ADC resolution; 0: none
  core::Vec3 current_offset_A = core::Vec3::Zero();
  core::Vec3 current_gain_error = core::Vec3::Zero();  ///< measured = true·(1 + gain) + offset
  double encoder_counts = 0.0;                         ///< counts per mechanical revolution; 0: ideal
  double theta_offset_rad = 0.0;                       ///< electrical; measured = true − offset
  HallConfig hall;                                     ///< Hall sensors instead of the encoder (hall_sensors.hpp)
  int speed_window = 8;                                ///< samples over which the speed is differentiated
  double u_dc_noise_V = 0.0;
  double u_dc_lsb_V = 0.0;
};

class Sensors {
 public:
  Sensors(const SensorConfig& config, int pole_pairs, double period_s, std::uint64_t seed);

  [[nodiscard]] core::Vec3 currents(const core::Vec3& i_abc_A) noexcept;
  /// Samples the angle (call once per period, before speed()); returns the measured electrical angle.
  [[nodiscard]] double angle(double theta_el_true_rad) noexcept;
  /// Speed from the measured angles of the last `speed_window` periods [electrical rad/s].
  [[nodiscard]] double speed() const noexcept;
  [[nodiscard]] double dc_link(double u_dc_V) noexcept;

 private:
  /// Rounds to a multiple of lsb (inv_lsb = 1/lsb; lsb 0: unchanged).
  [[nodiscard]] static double quantize(double x, double lsb, double inv_lsb) noexcept;

  SensorConfig config_;
  int pole_pairs_;
  double period_s_;
  // Reciprocals, so the per-period path multiplies instead of dividing.
  double inv_current_lsb_ = 0.0, inv_u_dc_lsb_ = 0.0, inv_pole_pairs_ = 1.0;
  double encoder_step_rad_ = 0.0, inv_encoder_step_ = 0.0;  ///< mechanical angle per count
  GaussianNoise normal_;
  HallSensors hall_;
  std::vector<double> angle_history_mech_;  ///< unwrapped measured mechanical angles, ring buffer
  std::size_t head_ = 0;
  std::size_t count_ = 0;
};

}  // namespace rpem::sim
