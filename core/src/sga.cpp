#include <algorithm>

#include "rpem/core/gain.hpp"

namespace rpem::core {

GainOutput sga_gain(const Mat2& gradient, const Vec2& gamma_hessian, const Vec2& gamma_gain,
                    const GainFloors& floors, Vec2& r) noexcept {
  const double trace = gradient.squaredNorm();  // tr{Ψ·Ψᵀ}, eq:traceSGAHessian
  GainOutput out;
  for (int j = 0; j < 2; ++j) {
    r[j] += gamma_hessian[j] * (trace - r[j]);
    double denominator = r[j];
    if (denominator < floors.sga_hessian_min_pu) {
      denominator = floors.sga_hessian_min_pu;
      out.flags |= gain_flag::kFloored;
    }
    out.gain.row(j) = (gamma_gain[j] / denominator) * gradient.col(j).transpose();
  }
  return out;
}

}  // namespace rpem::core
