#include <cmath>

#include "rpem/core/assert.hpp"
#include "rpem/core/gain.hpp"

namespace rpem::core {

Mat2 symmetric_pseudo_inverse(const Mat2& r, double eigenvalue_min) noexcept {
  const double a = r(0, 0);
  const double b = 0.5 * (r(0, 1) + r(1, 0));
  const double c = r(1, 1);
  const double mean = 0.5 * (a + c);
  const double radius = std::hypot(0.5 * (a - c), b);
  const double lambda1 = mean + radius;
  const double lambda2 = mean - radius;

  // Unit eigenvector of λ1: the better-conditioned of the two candidate forms.
  Vec2 v1(1.0, 0.0);
  const Vec2 cand_a(b, lambda1 - a);
  const Vec2 cand_b(lambda1 - c, b);
  const Vec2& cand = cand_a.squaredNorm() >= cand_b.squaredNorm() ? cand_a : cand_b;
  if (cand.squaredNorm() > 0.0) {
    v1 = cand.normalized();
  } else if (c > a) {
    v1 = Vec2(0.0, 1.0);
  }
  const Vec2 v2(-v1[1], v1[0]);

  Mat2 pinv = Mat2::Zero();
  if (lambda1 > eigenvalue_min) pinv += (v1 * v1.transpose()) / lambda1;
  if (lambda2 > eigenvalue_min) pinv += (v2 * v2.transpose()) / lambda2;
  return pinv;
}

GainOutput gna_gain(const Mat2& gradient, double gamma_hessian, const Vec2& gamma_gain, const GainFloors& floors,
                    Mat2& hessian, int only) noexcept {
  RPEM_ASSERT(only == kBothParameters || only == 0 || only == 1, "only: one parameter's index, or both");
  const Mat2 psi = gradient.transpose();
  hessian += gamma_hessian * (psi * psi.transpose() - hessian);

  GainOutput out;
  if (only != kBothParameters) {
    const double r = hessian(only, only);
    if (r > floors.gna_eigenvalue_min_pu) {
      out.gain.row(only) = (gamma_gain[only] / r) * psi.row(only);
    } else {
      out.flags |= gain_flag::kPseudoInverse;  // R_jj's pseudo-inverse: 0
    }
    return out;
  }
  const double det = det2(hessian);  // |R|, eq:InverseR
  Mat2 inverse;
  if (det >= floors.gna_determinant_min_pu && det > 0.0) {
    inverse = adjugate2(hessian) / det;
  } else {
    inverse = symmetric_pseudo_inverse(hessian, floors.gna_eigenvalue_min_pu);
    out.flags |= gain_flag::kPseudoInverse;
  }
  out.gain = gamma_gain.asDiagonal() * inverse * psi;  // eq:GNA_GainElements
  return out;
}

}  // namespace rpem::core
