#include "rpem/sim/linear_flow.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::sim {
namespace {

/// The series stops at N once ρᴺ/N! ≤ this: the remainder is then below 1e-16 of ‖ψ₀‖ + t·‖c + u₀‖
/// (docs/derivations.md §10, with e^ρ ≤ e at ρ ≤ 1).
constexpr double kTermBound = 3.6e-17;

}  // namespace

void LinearFlow::prepare(const PmsmPlant& plant) noexcept {
  const PlantParameters& p = plant.parameters();
  omega_ = plant.period_speed();
  const double g = p.r_fe_Ohm > 0.0 ? omega_ / p.r_fe_Ohm : 0.0;  // iron-loss branch: (ω/R_fe)·J·ψ
  const double inv_ld = 1.0 / p.l_d_H, inv_lq = 1.0 / p.l_q_H;
  k_ << inv_ld, -g, g, inv_lq;
  k0_A_ = {inv_ld * p.psi_m_Wb, 0.0};
  c_V_ = p.r_s_Ohm * k0_A_;
  // A = −R_s·K − ω·J
  a_ << -p.r_s_Ohm * inv_ld, p.r_s_Ohm * g + omega_, -p.r_s_Ohm * g - omega_, -p.r_s_Ohm * inv_lq;
  mu_ = std::max(std::abs(a_(0, 0)) + std::abs(a_(0, 1)), std::abs(a_(1, 0)) + std::abs(a_(1, 1))) + std::abs(omega_);
}

void LinearFlow::start(const PmsmPlant& plant, const core::Vec2& u_ab_V, double h_max_s) noexcept {
  r0_ = plant.rotation();
  reach_s_ = mu_ * h_max_s > 1.0 ? 1.0 / mu_ : h_max_s;
  const double rho = mu_ * reach_s_;
  core::Vec2 w = core::park(u_ab_V, r0_);  // Ωⁿ⁻¹·u₀/(n−1)!, from n = 1
  coeff_[0] = plant.state().psi_Wb;
  coeff_[1] = a_ * coeff_[0] + c_V_ + w;
  double bound = rho;  // ρⁿ/n!
  int n = 1;
  while (bound > kTermBound && n < kMaxOrder) {
    w = (omega_ / n) * core::Vec2(w[1], -w[0]);  // Ω·w/n with Ω = −ω·J
    ++n;
    coeff_[n] = (a_ * coeff_[n - 1] + w) * (1.0 / n);
    bound *= rho / n;
  }
  order_ = n;
}

core::Vec2 LinearFlow::flux(double t_s) const noexcept {
  core::Vec2 psi = coeff_[order_];
  for (int n = order_ - 1; n >= 0; --n) psi = coeff_[n] + t_s * psi;
  return psi;
}

core::Vec2 LinearFlow::flux_rate(double t_s) const noexcept {
  core::Vec2 rate = order_ * coeff_[order_];
  for (int n = order_ - 1; n >= 1; --n) rate = n * coeff_[n] + t_s * rate;
  return rate;
}

PhaseCurrents LinearFlow::phases(double t_s) const noexcept {
  const core::Vec2 i = k_ * flux(t_s) - k0_A_;
  return phase_currents(i, k_ * flux_rate(t_s), core::compose(r0_, rotation_by(omega_ * t_s)), omega_);
}

void LinearFlow::commit(PmsmPlant& plant, double t_s) const noexcept {
  plant.move_to(flux(t_s), plant.magnetising_current(), t_s);
}

}  // namespace rpem::sim
