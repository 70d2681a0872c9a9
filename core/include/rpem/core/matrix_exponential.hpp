#pragma once
// The matrix exponential e^X of a small fixed-size matrix and φ₁(X) = Σ_k X^k/(k+1)! (so that
// ∫₀^Δt e^{A·s} ds = Δt·φ₁(A·Δt)), by scaling and squaring with Taylor series (docs/derivations.md §14,
// "Exact step"): X is scaled by 2^−s until its 1-norm is at most ½, both series are summed until a term
// no longer changes the sums in double precision (at most kMaxTerms terms: the remainder at ‖X‖ ≤ ½ after 18
// terms is below 10⁻²²), then doubled s times with e^{2X} = (e^X)² and φ₁(2X) = ½·φ₁(X)·(e^X + I).
// Real-time safe: fixed-size Eigen, no allocation; the cost grows with ‖X‖ (a thermal step of 0.1 s whose
// fastest time constant is seconds needs no doubling and four or five terms).

#include <Eigen/Core>
#include <cmath>

namespace rpem::core {

template <int N>
struct ExponentialPair {
  Eigen::Matrix<double, N, N> exp;   ///< e^X
  Eigen::Matrix<double, N, N> phi1;  ///< φ₁(X)
};

template <int N>
[[nodiscard]] ExponentialPair<N> exponential_and_phi1(const Eigen::Matrix<double, N, N>& m) noexcept {
  using Mat = Eigen::Matrix<double, N, N>;
  constexpr int kMaxTerms = 18;
  constexpr int kMaxSquarings = 60;                             // 2^60: beyond any finite norm a thermal network produces
  const double norm = m.cwiseAbs().colwise().sum().maxCoeff();  // the 1-norm
  int squarings = 0;
  if (norm > 0.5) squarings = static_cast<int>(std::ceil(std::log2(norm / 0.5)));
  if (!(squarings <= kMaxSquarings)) squarings = kMaxSquarings;  // also catches a NaN norm
  const Mat x = m * std::ldexp(1.0, -squarings);
  // term_k = X^k/(k+1)!: φ₁ sums them, e^X = I + X·φ₁.
  Mat phi = Mat::Identity();
  Mat term = Mat::Identity();
  for (int k = 1; k <= kMaxTerms; ++k) {
    term = (term * x) * (1.0 / static_cast<double>(k + 1));  // one division, not one per coefficient
    phi += term;
    if (term.cwiseAbs().maxCoeff() <= 1e-17 * phi.cwiseAbs().maxCoeff()) break;
  }
  Mat e = Mat::Identity() + x * phi;
  for (int k = 0; k < squarings; ++k) {
    phi = (0.5 * phi * (e + Mat::Identity())).eval();
    e = (e * e).eval();
  }
  return {e, phi};
}

template <int N>
[[nodiscard]] Eigen::Matrix<double, N, N> matrix_exponential(const Eigen::Matrix<double, N, N>& m) noexcept {
  return exponential_and_phi1<N>(m).exp;
}

}  // namespace rpem::core
