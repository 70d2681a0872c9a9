#include <cmath>

#include "rpem/core/gain.hpp"

namespace rpem::core {

GainOutput phyint_gain(const MachinePu& m, double n_pu, const Vec2& i_hat_pu, const Vec2& gamma_gain,
                       const GainFloors& floors) noexcept {
  GainOutput out;
  out.gain(kPsiM, 0) = -gamma_gain[kPsiM] * m.x_d_pu;  // eq:PhyInterPRet

  // eq:PhyInterPRet_Rs: each component inverts its own steady-state sensitivity ε_j ≈ (den_j/D)·δr̂s.
  const double d = steady_state_denominator(m, n_pu);
  const Vec2 den(-m.r_s_pu * i_hat_pu[0] - n_pu * m.x_q_pu * i_hat_pu[1],
                 -m.r_s_pu * i_hat_pu[1] + n_pu * m.x_d_pu * i_hat_pu[0]);
  int used = 0;
  for (int j = 0; j < 2; ++j) {
    if (std::abs(den[j]) >= floors.phyint_denominator_min_pu) {
      ++used;
    } else {
      out.flags |= gain_flag::kFloored;
    }
  }
  if (used == 0) return out;
  for (int j = 0; j < 2; ++j) {
    if (std::abs(den[j]) >= floors.phyint_denominator_min_pu) {
      out.gain(kRs, j) = gamma_gain[kRs] * d / (used * den[j]);
    }
  }
  return out;
}

}  // namespace rpem::core
