#pragma once
// A rotor whose speed profile is known, and a type-2 PLL run on it as VESC's firmware runs it, read every few control
// cycles: written from the PLL's equations (docs/derivations.md §13 "Speed at the read": θ̂ += (ω̂ + k_p·e)·dt,
// ω̂ += k_i·e·dt, e = θ − θ̂, once per control cycle), not from the code under test. Each window carries the rotor's
// true mean speed over it beside the PLL's speed at the read that ends it and core::window_mean_speed_rad_s's rebuild.

#include <cstdint>
#include <functional>
#include <vector>

#include "rpem/core/frames.hpp"
#include "rpem/core/reported_speed.hpp"

namespace rpem::test {

inline constexpr double kPllKp = 2000.0, kPllKi = 30000.0;  // vedderb/bldc motor/mcconf_default.h's defaults
inline constexpr double kPllCycleS = 80e-6;                 // one control cycle
inline constexpr std::int64_t kPllCycleNs = 80'000;

struct PllWindow {
  double true_mean = 0.0;  // the rotor's mean speed over the window
  double rebuilt = 0.0;    // window_mean_speed_rad_s from the PLL's speeds at its reads
  double at_read = 0.0;    // the PLL's speed at the read, as reported
  double t_s = 0.0;        // the read's time
};

/// Runs the rotor (speed ω(t)) and the PLL for `duration_s`, read every `read_cycles` cycles.
inline std::vector<PllWindow> run_pll(const std::function<double(double)>& omega, double duration_s, int read_cycles) {
  double theta = 0.0, theta_hat = 0.0, omega_hat = omega(0.0);
  std::vector<PllWindow> out;
  core::SpeedRead previous{0, omega_hat};
  double sum = 0.0;
  const auto cycles = static_cast<std::int64_t>(duration_s / kPllCycleS);
  for (std::int64_t n = 1; n <= cycles; ++n) {
    const double t = static_cast<double>(n - 1) * kPllCycleS;
    // The rotor over the cycle (midpoint rule: exact for piecewise-linear profiles).
    const double w = omega(t + 0.5 * kPllCycleS);
    theta = core::wrap_angle(theta + w * kPllCycleS);
    sum += w * kPllCycleS;
    const double e = core::wrap_angle(theta - theta_hat);
    theta_hat = core::wrap_angle(theta_hat + (omega_hat + kPllKp * e) * kPllCycleS);
    omega_hat += kPllKi * e * kPllCycleS;
    if (n % read_cycles == 0) {
      const core::SpeedRead now{n * kPllCycleNs, omega_hat};
      const double h = static_cast<double>(read_cycles) * kPllCycleS;
      out.push_back({sum / h,
                     core::window_mean_speed_rad_s(previous, now, previous.t_ns, core::pll_ramp_lag_s(kPllKp, kPllKi)),
                     omega_hat, t + kPllCycleS});
      previous = now;
      sum = 0.0;
    }
  }
  return out;
}

}  // namespace rpem::test
