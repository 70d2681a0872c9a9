#pragma once
// Operating profiles: speed and current over time, piecewise linear, a repeated time a step (README.md,
// "Profiles"). A profile file is CSV with the header `t_s,speed_rpm,i_q_A[,i_d_A]`; without i_d_A the drive
// chooses i_d (electrical.hpp). Built in: `heat-cool` (a heat-up at speed and high current, then a cool-down
// at the same speed and lower current, like Paderborn profile A) and `drive-cycle` (seeded: load blocks of
// cruise, high speed at low current, hard acceleration, regeneration and standstill with current, between
// rest blocks that begin with an idle and a standstill with current, then idle or light load).
#include <cstdint>
#include <string>
#include <vector>

#include "indep_thermal/electrical.hpp"
#include "indep_thermal/machine.hpp"

namespace indep_thermal {

struct ProfilePoint {
  double t_s = 0.0;
  double speed_rpm = 0.0;
  double i_q_A = 0.0;
  double i_d_A = 0.0;  // used when the profile gives i_d
};

struct Profile {
  std::string name;
  bool gives_i_d = false;
  std::vector<ProfilePoint> points;  // time non-decreasing; two points at one time make a step

  /// The demand at t: linear between points; at a step, the later point (the earlier with `left_limit`, the
  /// limit from before t, which an integration step ending at a knot needs); held before the first and after
  /// the last point.
  [[nodiscard]] Demand at(double t_s, bool left_limit = false) const;
  /// The distinct times of the points (where the demand may bend or step), increasing.
  [[nodiscard]] std::vector<double> knots() const;
};

/// Reads a profile CSV; throws DataError `file:line:column: reason`.
Profile read_profile_csv(const std::string& path);

/// Heat-up then cool-down at 0.917·N_n: standstill until min(60 s, 1 % of the duration), a 12 s ramp to
/// i_d = −0.885·Î_n, i_q = 0.29·Î_n, held to 58.6 % of the duration, then i_d = −0.47·Î_n, i_q = 0 (the
/// proportions of Paderborn profile A: 4400 s of 7505 s, −200/66 A then −107/0.6 A of Î_n ≈ 226 A).
Profile heat_cool_profile(const Machine& machine, double duration_s);

/// A seeded drive cycle (README.md, "Profiles"); the drive chooses i_d. `load_scale` multiplies every
/// q current of it.
Profile drive_cycle_profile(const Machine& machine, double duration_s, std::uint64_t seed, double load_scale = 1.0);

}  // namespace indep_thermal
