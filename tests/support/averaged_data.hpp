#pragma once
// Averaged rotor-frame samples computed from the machine equations directly (no simulator, no
// estimator code): windows of uneven length (uniform in (1 ± jitter)/rate, clipped to [0.5, 20] ms, as
// the sources deliver), over which the current moves linearly at constant speed. For such a
// window the exact means satisfy (docs/derivations.md §1, averaged over the window)
//   ū = r·ī + (x/ω_n)·di/dt + n·J·x·ī + n·J·[0, ψm]ᵀ
// because the mean of a linear function is its value at the window's centre.

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/machine.hpp"
#include "rpem/core/per_unit.hpp"

namespace rpem::test {

struct AveragedDataGenerator {
  core::PerUnitBase base;
  core::MachinePu plant;  ///< the true machine, pu
  double rate_Hz = 200.0;
  double jitter = 0.3;
  std::function<double(double)> n_pu = [](double) { return 0.0; };                            ///< speed at t [s]
  std::function<core::Vec2(double)> i_pu = [](double) { return core::Vec2::Zero(); };         ///< current at t
  std::function<core::Vec2(double)> di_pu_per_s = [](double) { return core::Vec2::Zero(); };  ///< its slope
  std::mt19937_64 rng{1};
  double t_s = 0.0;

  /// The next window [t, t + h] with its exact means.
  core::AveragedSample next() {
    std::uniform_real_distribution<double> u(1.0 - jitter, 1.0 + jitter);
    const double h = std::clamp(u(rng) / rate_Hz, 0.5e-3, 20e-3);
    const double t0 = t_s, t1 = t_s + h, c = 0.5 * (t0 + t1);
    t_s = t1;
    const double n = n_pu(c);
    const core::Vec2 i = i_pu(c);
    const core::Vec2 di = di_pu_per_s(c);
    const core::Vec2 u_pu = core::steady_state_voltage(plant, n, i) +
                            core::Vec2(plant.x_d_pu * di[0], plant.x_q_pu * di[1]) / base.omega_el_rad_s;
    core::AveragedSample s;
    s.t_start_ns = std::llround(t0 * 1e9);
    s.t_ns = std::llround(t1 * 1e9);
    s.i_dq_A = i * base.current_A;
    s.u_dq_V = u_pu * base.voltage_V;
    s.omega_el_rad_s = base.omega_el_rad_s_of(n);
    s.u_dc_V = 560.0;
    return s;
  }
};

}  // namespace rpem::test
