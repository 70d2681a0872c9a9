#pragma once
// The sensorless angle: a rotor-flux observer and a phase-locked loop, the two blocks a sensorless VESC runs
// every control cycle (README "Firmware"). Written from the published observer, not from VESC's code:
//
//   J. Lee, J. Hong, K. Nam, R. Ortega, L. Praly, A. Astolfi, "Sensorless control of surface-mount permanent-
//   magnet synchronous motors based on a nonlinear observer", IEEE Trans. Power Electron. 25(2), 2010:
//     dx/dt = v − R·i + (γ/2)·η·(ψ² − |η|²),   η = x − L·i,   θ̂ = atan2(η_β, η_α)
//   integrated with forward Euler at the control period, with the VESC's configured R and L; the flux linkage ψ
//   in it is adapted along the gradient of the same mismatch, dψ̂/dt = κ·ψ̂·(|η|² − ψ̂²), κ = 0.1·γ/2, within
//   [0.3, 2.5]× the configured ψ: a gradient estimate of the magnet flux after P. Bernard and L. Praly (IFAC
//   World Congress 2017, the paper bldc's motor/foc_math.c cites); the VESC's default observer adapts its λ too.
//
// PLL (second order, type 2): e = wrap(θ − θ̂),  θ̂ += (ω̂ + k_p·e)·dt,  ω̂ += k_i·e·dt.
#include "indep_drive/frames.hpp"

namespace indep::vesc {

using indep::Vec2;

/// Angle wrapped to (−π, π].
double wrap_pi(double a);

class FluxObserver {
 public:
  FluxObserver(double r_Ohm, double l_H, double psi_Wb) : r_(r_Ohm), l_(l_H), psi_(psi_Wb), psi_hat_(psi_Wb) {}
  /// A new configured ψ (the adapted one restarts there).
  void set_flux_linkage(double psi_Wb) { psi_ = psi_hat_ = psi_Wb; }
  [[nodiscard]] double flux_linkage() const { return psi_hat_; }

  /// One Euler step with the stationary-frame voltage and current of this cycle; gamma [1/(Wb²·s)].
  void update(Vec2 v_ab_V, Vec2 i_ab_A, double dt_s, double gamma);
  /// Sets the state so that the rotor-flux estimate is psi·e^{jangle} at current i_ab.
  void force(double angle_rad, Vec2 i_ab_A);
  [[nodiscard]] double angle_rad() const;
  [[nodiscard]] Vec2 rotor_flux_Wb() const { return eta_; }

 private:
  double r_, l_, psi_, psi_hat_;
  Vec2 x_{0.0, 0.0};
  Vec2 eta_{0.0, 0.0};
};

class Pll {
 public:
  Pll(double kp, double ki) : kp_(kp), ki_(ki) {}
  void update(double angle_rad, double dt_s);
  [[nodiscard]] double speed_rad_s() const { return speed_; }
  [[nodiscard]] double angle_rad() const { return angle_; }
  /// Limits |ω̂| (wind-up protection against a fast speed estimate).
  void clamp_speed(double max_abs_rad_s);

 private:
  double kp_, ki_;
  double angle_ = 0.0, speed_ = 0.0;
};

}  // namespace indep::vesc
