#pragma once
// Classical fourth-order Runge–Kutta on the plant's flux-linkage and angle states over one step of length h
// with the leg voltages held (zero-order hold within a PWM period). `drivers(t)` gives ω, R_s, ψm at t.
#include <array>

#include "indep_drive/plant.hpp"

namespace indep {

/// Advances x by h from t; k1 is the plant evaluated at (t, x). Returns the evaluation at (t + h, x_new).
template <class Drivers>
PlantEval rk4_step(const Plant& plant, PlantState& x, const PlantEval& k1, double t, double h,
                   const std::array<double, 3>& legs, const Drivers& drivers) {
  const Operating o1 = drivers(t), o2 = drivers(t + 0.5 * h), o4 = drivers(t + h);
  auto stage = [&](const PlantEval& k, double dt, double omega) {
    PlantState s = x;
    s.psi_Wb = x.psi_Wb + dt * k.dpsi_dt;
    s.theta_rad = x.theta_rad + dt * omega;
    s.i_m_A = k.i_m_A;
    return s;
  };
  const PlantEval k2 = plant.evaluate(stage(k1, 0.5 * h, o1.omega_el_rad_s), legs, o2);
  const PlantEval k3 = plant.evaluate(stage(k2, 0.5 * h, o2.omega_el_rad_s), legs, o2);
  const PlantEval k4 = plant.evaluate(stage(k3, h, o2.omega_el_rad_s), legs, o4);
  x.psi_Wb = x.psi_Wb + (h / 6.0) * (k1.dpsi_dt + 2.0 * k2.dpsi_dt + 2.0 * k3.dpsi_dt + k4.dpsi_dt);
  x.theta_rad += (h / 6.0) * (o1.omega_el_rad_s + 4.0 * o2.omega_el_rad_s + o4.omega_el_rad_s);
  x.i_m_A = k4.i_m_A;
  return plant.evaluate(x, legs, o4);
}

}  // namespace indep
