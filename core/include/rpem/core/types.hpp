#pragma once
// Fixed-size linear-algebra types used throughout the estimator core. Nothing here allocates.

#include <Eigen/Core>
#include <numbers>

namespace rpem::core {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kSqrt3 = 1.7320508075688772;
inline constexpr double kInvSqrt3 = 1.0 / kSqrt3;  ///< per-sample code multiplies (a division costs ~4× more)

using Vec2 = Eigen::Matrix<double, 2, 1>;
using Vec3 = Eigen::Matrix<double, 3, 1>;
using Mat2 = Eigen::Matrix<double, 2, 2>;

/// Index of each identified parameter in the parameter vector θ̂ = [ψ̂m, r̂s]ᵀ (eq:ParamVectorModified).
enum class Param : int { kPsiM = 0, kRs = 1 };
inline constexpr int kPsiM = static_cast<int>(Param::kPsiM);
inline constexpr int kRs = static_cast<int>(Param::kRs);

/// 0 if x is finite, NaN if it is ±∞ or NaN (x·0); for a vector, the sum over its elements.
[[nodiscard]] inline double finite_probe(double x) noexcept { return x * 0.0; }
template <typename Derived>
[[nodiscard]] double finite_probe(const Eigen::MatrixBase<Derived>& v) noexcept {
  return (v * 0.0).sum();
}

/// Whether every value (scalars, fixed-size vectors) is finite, with one comparison: the probes sum to 0
/// exactly when all are finite (they are 0 or NaN, so no sum of them can overflow).
template <typename... Values>
[[nodiscard]] bool all_finite(const Values&... x) noexcept {
  return (finite_probe(x) + ... + 0.0) == 0.0;
}

/// Determinant of a 2×2 matrix.
[[nodiscard]] inline double det2(const Mat2& m) noexcept { return m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0); }

/// Adjugate of a 2×2 matrix: adj(M) = det(M)·M⁻¹.
[[nodiscard]] inline Mat2 adjugate2(const Mat2& m) noexcept {
  Mat2 a;
  a << m(1, 1), -m(0, 1), -m(1, 0), m(0, 0);
  return a;
}

/// Closed-form inverse of a 2×2 matrix (the caller guarantees det ≠ 0).
[[nodiscard]] inline Mat2 inverse2(const Mat2& m) noexcept { return adjugate2(m) / det2(m); }

}  // namespace rpem::core
