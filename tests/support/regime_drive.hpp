#pragma once
// A drive as a slow logger sees it, from the machine's rotor-frame equations alone (no simulator, no
// estimator code): the voltage u = R·i + L·di/dt + ω·J·L·i + ω·J·[ψm, 0] of a machine whose parameters
// are off the configuration, integrated on a fine grid (50 µs) and averaged over windows of uneven length
// the way a VESC Tool realtime log holds them (means since the previous read), with the regimes real
// drives pass through (issue 23):
//   - open-loop start-up: the current held in a commanded frame that leads the rotor by the load angle δ
//     (cos δ = τ_load/(ψm·I): the rotor lags until the held current's torque meets the load), the voltage
//     reported in that frame;
//   - closed loop: the current follows its reference in the rotor frame;
//   - bridge off: the drive reports u = 0 and the current is zero (freewheeling below the DC link);
//   - coasting at zero current with the bridge modulating (u = the back-EMF);
//   - hard accelerations inside a window.
// Means carry white noise and the log's quantisation (VESC Tool's decimals).

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/types.hpp"

namespace rpem::test {

enum class DriveMode { kOpenLoop, kClosedLoop, kBridgeOff, kCoast };

/// One segment of the drive cycle: from its start to its end the speed moves linearly from omega_start to
/// omega_end and the current (rotor frame in closed loop, commanded frame in open loop) from i_start to i_end.
struct DriveSegment {
  double seconds;
  DriveMode mode;
  double omega_start_rad_s, omega_end_rad_s;
  core::Vec2 i_start_A, i_end_A;
  double load_angle_rad = 0.0;  ///< open loop: how far the commanded frame leads the rotor
  double window_s = 0.09;       ///< the logger's mean read interval during this segment
};

struct RegimeDrive {
  double r_s_Ohm = 0.025, l_d_H = 20e-6, l_q_H = 20e-6, psi_m_Wb = 0.004633;  ///< the true machine
  double fine_step_s = 50e-6;
  double jitter = 0.3;  ///< window lengths uniform in (1 ± jitter)·window_s
  double current_noise_A = 0.05, voltage_noise_V = 0.002, speed_noise_rad_s = 0.5;
  double current_quantum_A = 0.01, voltage_quantum_V = 0.001, erpm_quantum = 1.0;
  std::uint64_t seed = 1;

  struct Window {
    core::AveragedSample sample;
    DriveMode mode;      ///< the mode at the window's end
    bool mixed = false;  ///< the window holds more than one segment
  };

  /// The windows of the cycle, each with its means, in the order a logger writes them.
  [[nodiscard]] std::vector<Window> windows(const std::vector<DriveSegment>& cycle) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> spread(1.0 - jitter, 1.0 + jitter);
    std::normal_distribution<double> unit(0.0, 1.0);
    std::vector<Window> out;
    double t = 0.0, total = 0.0;
    for (const DriveSegment& s : cycle) total += s.seconds;
    std::size_t seg = 0;
    double seg_start = 0.0;
    core::Vec2 i_prev = point(cycle[0], 0.0).i_rotor;
    while (t < total - 1e-9) {
      const double h = std::min(cycle[seg].window_s * spread(rng), total - t);
      const std::size_t first_seg = seg;
      core::Vec2 u_sum = core::Vec2::Zero(), i_sum = core::Vec2::Zero();
      double w_sum = 0.0;
      const int steps = std::max(1, static_cast<int>(std::lround(h / fine_step_s)));
      const double dt = h / steps;
      bool off_all = true;
      for (int k = 0; k < steps; ++k) {
        const double tk = t + (k + 1) * dt;
        while (seg + 1 < cycle.size() && tk > seg_start + cycle[seg].seconds) {
          seg_start += cycle[seg].seconds;
          ++seg;
        }
        const Point p = point(cycle[seg], tk - seg_start);
        // The rotor-frame voltage over this fine step (L·di/dt by the step's difference: its integral exact).
        const core::Vec2 di = (p.i_rotor - i_prev) / dt;
        i_prev = p.i_rotor;
        core::Vec2 u_rotor(r_s_Ohm * p.i_rotor[0] + l_d_H * di[0] - p.omega * l_q_H * p.i_rotor[1],
                           r_s_Ohm * p.i_rotor[1] + l_q_H * di[1] + p.omega * (l_d_H * p.i_rotor[0] + psi_m_Wb));
        core::Vec2 i_frame = p.i_rotor;
        if (cycle[seg].mode == DriveMode::kOpenLoop) {
          u_rotor = to_frame(u_rotor, p.delta);
          i_frame = to_frame(p.i_rotor, p.delta);
        }
        if (cycle[seg].mode == DriveMode::kBridgeOff) {
          u_rotor.setZero();  // the drive reports no voltage; the machine's current is zero
        } else {
          off_all = false;
        }
        u_sum += u_rotor;
        i_sum += i_frame;
        w_sum += p.omega;
      }
      Window w;
      w.mode = cycle[seg].mode;
      w.mixed = seg != first_seg;
      core::AveragedSample& a = w.sample;
      a.t_start_ns = std::llround(t * 1e9);
      t += h;
      a.t_ns = std::llround(t * 1e9);
      const double noise_scale = std::sqrt(0.09 / h);  // means over longer windows are quieter
      a.i_dq_A =
          quantise(i_sum / steps + current_noise_A * noise_scale * core::Vec2(unit(rng), unit(rng)), current_quantum_A);
      if (off_all) a.i_dq_A = quantise(current_noise_A * noise_scale * core::Vec2(unit(rng), unit(rng)), current_quantum_A);
      a.u_dq_V = off_all ? core::Vec2::Zero()
                         : quantise(u_sum / steps + voltage_noise_V * noise_scale * core::Vec2(unit(rng), unit(rng)),
                                    voltage_quantum_V);
      // The speed as VESC Tool logs it: electrical rpm, whole numbers.
      const double erpm = (w_sum / steps + speed_noise_rad_s * noise_scale * unit(rng)) * 60.0 / (2.0 * core::kPi);
      a.omega_el_rad_s = erpm_quantum * std::round(erpm / erpm_quantum) * 2.0 * core::kPi / 60.0;
      a.u_dc_V = 40.0;
      out.push_back(w);
    }
    return out;
  }

 private:
  struct Point {
    double omega;
    core::Vec2 i_rotor;
    double delta;
  };
  /// The operating point `tau` seconds into a segment.
  static Point point(const DriveSegment& s, double tau) {
    const double f = std::clamp(tau / s.seconds, 0.0, 1.0);
    Point p;
    p.omega = s.omega_start_rad_s + f * (s.omega_end_rad_s - s.omega_start_rad_s);
    const core::Vec2 i = s.i_start_A + f * (s.i_end_A - s.i_start_A);
    p.delta = s.mode == DriveMode::kOpenLoop ? s.load_angle_rad : 0.0;
    switch (s.mode) {
      case DriveMode::kOpenLoop:
        p.i_rotor = from_frame(i, p.delta);  // held in the commanded frame
        break;
      case DriveMode::kClosedLoop:
        p.i_rotor = i;
        break;
      case DriveMode::kBridgeOff:
      case DriveMode::kCoast:
        p.i_rotor.setZero();
        break;
    }
    return p;
  }
  /// Rotor-frame coordinates of a vector given in a frame δ ahead of the rotor, and back.
  static core::Vec2 from_frame(const core::Vec2& v, double delta) {
    return {std::cos(delta) * v[0] - std::sin(delta) * v[1], std::sin(delta) * v[0] + std::cos(delta) * v[1]};
  }
  static core::Vec2 to_frame(const core::Vec2& v, double delta) { return from_frame(v, -delta); }
  static core::Vec2 quantise(const core::Vec2& v, double q) { return {q * std::round(v[0] / q), q * std::round(v[1] / q)}; }
};

}  // namespace rpem::test
