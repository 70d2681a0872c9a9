#include "indep_drive/plant.hpp"

#include <cmath>
#include <utility>

namespace indep {

Vec2 HarmonicFlux::value(double theta) const {
  Vec2 h;
  for (int k = 0; k < count; ++k) {
    const HarmonicPair& p = pairs[static_cast<std::size_t>(k)];
    const double a_lo = p.phi_lo_rad - p.order * theta, a_hi = p.phi_hi_rad + p.order * theta;
    h = h + Vec2{p.h_lo_rel * std::cos(a_lo) + p.h_hi_rel * std::cos(a_hi),
                 p.h_lo_rel * std::sin(a_lo) + p.h_hi_rel * std::sin(a_hi)};
  }
  return h;
}

Vec2 HarmonicFlux::derivative(double theta) const {
  Vec2 d;
  for (int k = 0; k < count; ++k) {
    const HarmonicPair& p = pairs[static_cast<std::size_t>(k)];
    const double a_lo = p.phi_lo_rad - p.order * theta, a_hi = p.phi_hi_rad + p.order * theta;
    // d/dθ e^{j(φ − nθ)} = −jn·e^{j(φ − nθ)},  d/dθ e^{j(φ + nθ)} = +jn·e^{j(φ + nθ)}
    const Vec2 lo{p.h_lo_rel * std::cos(a_lo), p.h_lo_rel * std::sin(a_lo)};
    const Vec2 hi{p.h_hi_rel * std::cos(a_hi), p.h_hi_rel * std::sin(a_hi)};
    d = d + static_cast<double>(p.order) * (rot90(hi) - rot90(lo));
  }
  return d;
}

double DeadTime::error_V(double i_A) const { return -amplitude_V * std::tanh(i_A / band_A); }

Plant::Plant(FluxModel flux, HarmonicFlux harmonics, double r_fe_Ohm, DeadTime dead_time, bool dead_time_on)
    : flux_(std::move(flux)), harmonics_(harmonics), r_fe_(r_fe_Ohm), dead_time_(dead_time), dead_time_on_(dead_time_on) {}

PlantEval Plant::evaluate(const PlantState& x, const std::array<double, 3>& v_leg, const Operating& op) const {
  PlantEval e;
  const Vec2 psi_map = x.psi_Wb - op.psi_m_Wb * harmonics_.value(x.theta_rad);
  e.i_m_A = flux_.current(psi_map, op.psi_m_Wb, x.i_m_A);
  const bool iron = std::isfinite(r_fe_);
  // Dead time sees the magnetising current plus the loss current of the speed voltage (README "Iron loss").
  const Vec2 i_switch = iron ? e.i_m_A + (op.omega_el_rad_s / r_fe_) * rot90(x.psi_Wb) : e.i_m_A;
  std::array<double, 3> v = v_leg;
  if (dead_time_on_) {
    const std::array<double, 3> i_abc = inverse_clarke(inverse_park(i_switch, x.theta_rad));
    for (std::size_t k = 0; k < 3; ++k) v[k] += dead_time_.error_V(i_abc[k]);
  }
  e.u_V = park(clarke(v), x.theta_rad);
  // Induced voltage e = dψ/dt + ω·J·ψ across R_fe: e = u − R_s·(i_m + e/R_fe)  ⇒  e = (u − R_s·i_m)/(1 + R_s/R_fe).
  const double k = iron ? 1.0 / (1.0 + op.r_s_Ohm / r_fe_) : 1.0;
  const Vec2 induced = k * (e.u_V - op.r_s_Ohm * e.i_m_A);
  e.i_A = iron ? e.i_m_A + (1.0 / r_fe_) * induced : e.i_m_A;
  e.dpsi_dt = induced - op.omega_el_rad_s * rot90(x.psi_Wb);
  e.i_abc_A = inverse_clarke(inverse_park(e.i_A, x.theta_rad));
  return e;
}

double Plant::torque_Nm(const PlantState& x, const PlantEval& e, const Operating& op, int pole_pairs) const {
  const Vec2 psi = x.psi_Wb;
  const double reluctance_and_magnet = psi.x * e.i_m_A.y - psi.y * e.i_m_A.x;
  const double harmonic = op.psi_m_Wb * e.i_m_A.dot(harmonics_.derivative(x.theta_rad));
  return 1.5 * pole_pairs * (reluctance_and_magnet + harmonic);
}

double Plant::field_energy_J(const PlantEval& e, const Operating& op) const {
  const Vec2 psi_map = flux_.flux(e.i_m_A, op.psi_m_Wb);
  return 1.5 * (e.i_m_A.dot(psi_map) - flux_.coenergy(e.i_m_A, op.psi_m_Wb));
}

double Plant::iron_loss_W(const PlantEval& e) const {
  if (!std::isfinite(r_fe_)) return 0.0;
  const Vec2 i_fe = e.i_A - e.i_m_A;
  return 1.5 * r_fe_ * i_fe.dot(i_fe);
}

}  // namespace indep
