#pragma once
// Shared set-up of the independent thermal plant's tests: the configured machines and small helpers.
#include <limits>
#include <string>

#include "indep_thermal/generator.hpp"
#include "indep_thermal/machine.hpp"
#include "indep_thermal/profile.hpp"

namespace indep_thermal::test {

inline std::string config_path(const std::string& name) {
  return std::string(RPEM_TEST_SOURCE_DIR) + "/config/" + name + ".yaml";
}

inline Machine paper_machine() { return read_machine(config_path("paper-ipmsm")); }
inline Machine paderborn_machine() { return read_machine(config_path("paderborn-pmsm")); }

/// A profile holding one operating point from t = 0 (i_d given).
inline Profile constant_profile(double speed_rpm, double i_d_A, double i_q_A, double duration_s) {
  Profile p;
  p.name = "constant";
  p.gives_i_d = true;
  p.points = {{0.0, speed_rpm, i_q_A, i_d_A}, {duration_s, speed_rpm, i_q_A, i_d_A}};
  return p;
}

/// A case with exact logging (no noise) and constant coolant.
inline Case exact_case(const Machine& m, const Parameters& p, const Profile& profile, double duration_s, double rate_Hz) {
  Case c;
  c.machine = m;
  c.params = p;
  c.profile = profile;
  c.coolant = CoolantMode::constant;
  c.duration_s = duration_s;
  c.rate_Hz = rate_Hz;
  c.noise = false;
  return c;
}

/// A case holding one operating point (`constant_profile`), logged exactly. The inputs do not change, so the
/// step is the error control's alone: Case's 0.25 s cap, which resolves the drive's inputs between rows, has
/// nothing to resolve here, and would take 10⁵ steps for a settling time of hours. Without the cap a step may
/// grow until its error reaches the control's allowance, rtol·|T| (1.4e-6 K at 136 °C with Case's 1e-8): rtol
/// 1e-10 keeps that a hundredth of the 1e-6 K the steady-state tests assert.
inline Case steady_case(const Machine& m, const Parameters& p, double speed_rpm, double i_d_A, double i_q_A,
                        double duration_s, double rate_Hz) {
  Case c = exact_case(m, p, constant_profile(speed_rpm, i_d_A, i_q_A, duration_s), duration_s, rate_Hz);
  c.control.max_step = std::numeric_limits<double>::infinity();
  c.control.rtol = c.control.atol = 1e-10;
  return c;
}

}  // namespace indep_thermal::test
