#include "rpem/sim/magnetics.hpp"

namespace rpem::sim {

void Magnetics::prepare(const PlantParameters& p) noexcept {
  psi_m_Wb_ = p.psi_m_Wb;
  l_d_H_ = p.l_d_H;
  l_q_H_ = p.l_q_H;
  inv_l_d_ = 1.0 / p.l_d_H;
  inv_l_q_ = 1.0 / p.l_q_H;
  if (map_) map_shift_Wb_ = p.psi_m_Wb - map_->magnet_flux_Wb();
}

core::Vec2 Magnetics::flux(const core::Vec2& i_A) const noexcept {
  if (!map_) return {l_d_H_ * i_A[0] + psi_m_Wb_, l_q_H_ * i_A[1]};
  core::Vec2 psi = map_->flux(i_A);
  psi[0] += map_shift_Wb_;
  return psi;
}

core::Vec2 Magnetics::current(const core::Vec2& psi_Wb, const core::Vec2& guess) const noexcept {
  if (!map_) return {(psi_Wb[0] - psi_m_Wb_) * inv_l_d_, psi_Wb[1] * inv_l_q_};
  core::Vec2 i = guess;
  for (int k = 0; k < 4; ++k) {
    const core::Vec2 residual = flux(i) - psi_Wb;
    const core::Vec2 step = core::inverse2(map_->jacobian(i)) * residual;
    i -= step;
    if (step.squaredNorm() < 1e-24) break;
  }
  return i;
}

}  // namespace rpem::sim
