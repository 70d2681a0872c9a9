#include <algorithm>

#include "rpem/core/gain.hpp"

namespace rpem::core {

GainOutput sga_gain(const Mat2& gradient, const Vec2& gamma_hessian, const Vec2& gamma_gain,
                    const GainFloors& floors, Vec2& r) noexcept {
  const double trace = gradient.squaredNorm();  // tr{Ψ·Ψᵀ}, eq:traceSGAHessian
  GainOutput out;
  r += gamma_hessian.cwiseProduct(Vec2::Constant(trace) - r);
  if (r.minCoeff() < floors.sga_hessian_min_pu) out.flags |= gain_flag::kFloored;
  const Vec2 scale = gamma_gain.cwiseQuotient(r.cwiseMax(floors.sga_hessian_min_pu));
  // Row j of L is scale_j·Ψ_jᵀ. Built a column at a time: Mat2 is column-major, and element-wise
  // stores would stall the caller's whole-column loads (store forwarding).
  out.gain.col(0) = scale.cwiseProduct(gradient.row(0).transpose());
  out.gain.col(1) = scale.cwiseProduct(gradient.row(1).transpose());
  return out;
}

}  // namespace rpem::core
