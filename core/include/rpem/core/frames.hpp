#pragma once
// Reference-frame transforms, amplitude-invariant. The estimator's inputs pass through these
// functions and nowhere else (SampleConditioner); the simulator and tools reuse them.
//
//   Clarke:  x_α = (2/3)(x_a − x_b/2 − x_c/2),  x_β = (x_b − x_c)/√3
//   Park:    x^r = T_ss^r(ϑ)·x^s = [cos ϑ  sin ϑ; −sin ϑ  cos ϑ]·x^s   (Eq_FullOrderModel)

#include <cmath>

#include "rpem/core/types.hpp"

namespace rpem::core {

/// cos and sin of the electrical angle, computed once and shared by a forward and an inverse Park.
struct Rotation {
  double cos = 1.0;
  double sin = 0.0;
  [[nodiscard]] static Rotation of(double theta_rad) noexcept { return {std::cos(theta_rad), std::sin(theta_rad)}; }
};

/// Clarke followed by a factor k, folded into the transform's two constants once (the conditioner's
/// SI → per-unit step): x_α = (2k/3)·(x_a − x_b/2 − x_c/2), x_β = (k/√3)·(x_b − x_c).
struct ScaledClarke {
  double alpha = 2.0 / 3.0;  ///< 2k/3
  double beta = kInvSqrt3;   ///< k/√3
  [[nodiscard]] static ScaledClarke of(double k) noexcept { return {(2.0 / 3.0) * k, kInvSqrt3 * k}; }
  [[nodiscard]] Vec2 operator()(const Vec3& abc) const noexcept {
    return {alpha * (abc[0] - 0.5 * abc[1] - 0.5 * abc[2]), (abc[1] - abc[2]) * beta};
  }
};

[[nodiscard]] inline Vec2 clarke(const Vec3& abc) noexcept { return ScaledClarke{}(abc); }

[[nodiscard]] inline Vec3 inverse_clarke(const Vec2& ab) noexcept {
  return {ab[0], -0.5 * ab[0] + 0.5 * kSqrt3 * ab[1], -0.5 * ab[0] - 0.5 * kSqrt3 * ab[1]};
}

/// Stator (αβ) → rotor (dq) frame.
[[nodiscard]] inline Vec2 park(const Vec2& ab, const Rotation& r) noexcept {
  return {r.cos * ab[0] + r.sin * ab[1], -r.sin * ab[0] + r.cos * ab[1]};
}

/// Rotor (dq) → stator (αβ) frame.
[[nodiscard]] inline Vec2 inverse_park(const Vec2& dq, const Rotation& r) noexcept {
  return {r.cos * dq[0] - r.sin * dq[1], r.sin * dq[0] + r.cos * dq[1]};
}

/// Wraps an angle to [−π, π] (arithmetic only: no libm call on the real-time path).
[[nodiscard]] inline double wrap_angle(double theta_rad) noexcept {
  constexpr double kInvTwoPi = 1.0 / (2.0 * kPi);
  const double turns = theta_rad * kInvTwoPi;
  const auto nearest = static_cast<double>(static_cast<long long>(turns + (turns >= 0.0 ? 0.5 : -0.5)));
  return theta_rad - 2.0 * kPi * nearest;
}

/// cos and sin of a small angle x (|x| ≤ 0.1) by Taylor series to x⁸ and x⁷: the first omitted terms,
/// x¹⁰/10! and x⁹/9!, stay below 3e-15 there. Evaluated in powers of x⁴ (Estrin's scheme) rather than
/// by Horner's rule: the pairs are independent, so the result waits for three products and sums in a
/// row instead of five (the rotor angle's rotation is on the estimator's per-sample path).
[[nodiscard]] inline Rotation small_rotation(double x) noexcept {
  constexpr double c2 = 1.0 / 2.0, c4 = 1.0 / 24.0, c6 = 1.0 / 720.0, c8 = 1.0 / 40320.0;  // 1/n!, folded
  constexpr double s3 = 1.0 / 6.0, s5 = 1.0 / 120.0, s7 = 1.0 / 5040.0;                    // at compile time
  const double x2 = x * x, x4 = x2 * x2;
  const double cos_low = 1.0 - c2 * x2, cos_high = (c4 - c6 * x2) + c8 * x4;  // 1 − x²/2!, x⁴/4! − x⁶/6! + x⁸/8!
  const double sin_low = 1.0 - s3 * x2, sin_high = s5 - s7 * x2;              // (sin x)/x, the same way
  return {cos_low + x4 * cos_high, x * (sin_low + x4 * sin_high)};
}

/// The rotation by the sum of the two angles.
[[nodiscard]] inline Rotation compose(const Rotation& a, const Rotation& b) noexcept {
  return {a.cos * b.cos - a.sin * b.sin, a.sin * b.cos + a.cos * b.sin};
}

/// The rotation by n times the angle (n ≥ 0): cos nϑ and sin nϑ by repeated squaring, no libm call.
[[nodiscard]] inline Rotation multiple(const Rotation& r, int n) noexcept {
  Rotation result, square = r;
  for (; n > 0; n >>= 1) {
    if (n & 1) result = compose(result, square);
    square = compose(square, square);
  }
  return result;
}

/// cos and sin of an angle that moves little between calls (a logged or measured rotor angle, sample by
/// sample): the previous rotation composed with the increment's small_rotation(), with an exact libm
/// evaluation every kExactEvery calls, after reset() and for increments beyond 0.1 rad. Composition
/// round-off stays below 1e-13 between exact evaluations.
class RotationTracker {
 public:
  static constexpr unsigned kExactEvery = 32;
  static constexpr double kLargestIncrement_rad = 0.1;  // small_rotation()'s range

  [[nodiscard]] Rotation at(double theta_rad) noexcept {
    if (valid_ && ++since_exact_ < kExactEvery) {
      // An increment in range needs no wrapping (wrap_angle leaves it as it is). A branch, tested first:
      // the usual sample's rotation then does not wait for the wrap's conversions.
      double step = theta_rad - theta_rad_;
      if (!in_range(step)) [[unlikely]]
        step = wrap_angle(step);
      if (in_range(step)) {
        rotation_ = compose(rotation_, small_rotation(step));
        theta_rad_ = theta_rad;
        return rotation_;
      }
    }
    since_exact_ = 0;
    valid_ = true;
    rotation_ = Rotation::of(theta_rad);
    theta_rad_ = theta_rad;
    return rotation_;
  }
  void reset() noexcept { valid_ = false; }

 private:
  static bool in_range(double step_rad) noexcept {
    return step_rad <= kLargestIncrement_rad && step_rad >= -kLargestIncrement_rad;
  }
  Rotation rotation_;
  double theta_rad_ = 0.0;
  unsigned since_exact_ = 0;
  bool valid_ = false;
};

}  // namespace rpem::core
