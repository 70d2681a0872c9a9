#pragma once
// Operating profile and temperatures (README "Profiles"). The shaft speed is held by a load machine
// (a dynamometer) along the speed profile; the drive follows the torque profile in current control.
#include <string>
#include <vector>

#include "indep_drive/machine_config.hpp"

namespace indep {

/// One breakpoint; the profile is piecewise linear between them, and two points at the same time make a step.
struct ProfilePoint {
  double t_s = 0.0;
  double speed_rpm = 0.0;     // mechanical
  double torque_Nm = 0.0;     // command
  double i_d_inject_A = 0.0;  // added to the MTPA d-axis current
};

class OperatingProfile {
 public:
  OperatingProfile() = default;
  /// Throws std::invalid_argument unless the times are non-decreasing and start at 0.
  explicit OperatingProfile(std::vector<ProfilePoint> points);
  [[nodiscard]] ProfilePoint at(double t_s) const;
  [[nodiscard]] const std::vector<ProfilePoint>& points() const { return points_; }

 private:
  std::vector<ProfilePoint> points_;
};

/// The built-in profile over `duration_s` (README "Profiles"): standstill under load, ramps to and through
/// reversal, torque steps, speeds up to `max_speed_pu` of rated and torques up to `max_torque_pu` of
/// 1.5·p·ψm·√2·I_n.
OperatingProfile default_profile(const MachineConfig& m, double duration_s, double max_speed_pu, double max_torque_pu);

/// Reads `t_s,speed_rpm,torque_Nm[,i_d_inject_A]` (header row required). Throws naming file and line.
OperatingProfile read_profile_csv(const std::string& path);

/// A first-order thermal trajectory T(t) = T_end + (T_start − T_end)·e^{−t/τ}; constant when T_end = T_start.
struct TemperatureTrack {
  double start_C = 25.0;
  double end_C = 25.0;
  double tau_s = 0.0;  // 0: duration/3 (resolved by the generator)
  [[nodiscard]] double at(double t_s) const;
};

}  // namespace indep
