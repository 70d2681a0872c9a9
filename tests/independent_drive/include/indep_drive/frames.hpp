#pragma once
// Reference frames of the independent generator (its own; README "Frames").
//
//   amplitude-invariant Clarke:  x_α = (2 x_a − x_b − x_c)/3,  x_β = (x_b − x_c)/√3
//   Park (rotor frame at θ):     x_d = x_α cos θ + x_β sin θ,  x_q = −x_α sin θ + x_β cos θ
//
// θ is the electrical angle of the rotor d axis (magnet north) measured from the phase-a axis, positive
// in the direction of rotation a → b → c. The common mode (x_a + x_b + x_c)/3 is dropped by Clarke.
#include <array>
#include <cmath>

namespace indep {

struct Vec2 {
  double x = 0.0;  // d or α
  double y = 0.0;  // q or β
  friend Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
  friend Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
  friend Vec2 operator*(double k, Vec2 a) { return {k * a.x, k * a.y}; }
  [[nodiscard]] double norm() const { return std::hypot(x, y); }
  [[nodiscard]] double dot(Vec2 b) const { return x * b.x + y * b.y; }
};

/// j·v: the rotation by +90° (the J matrix [[0, −1], [1, 0]]).
inline Vec2 rot90(Vec2 v) { return {-v.y, v.x}; }

/// e^{jφ}·v.
inline Vec2 rotate(Vec2 v, double phi) {
  const double c = std::cos(phi), s = std::sin(phi);
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}

inline constexpr double kSqrt3 = 1.7320508075688772;
inline constexpr double kPi = 3.14159265358979323846;

inline Vec2 clarke(const std::array<double, 3>& abc) {
  return {(2.0 * abc[0] - abc[1] - abc[2]) / 3.0, (abc[1] - abc[2]) / kSqrt3};
}

/// Zero-sequence-free phase values of a stator vector.
inline std::array<double, 3> inverse_clarke(Vec2 ab) {
  return {ab.x, -0.5 * ab.x + 0.5 * kSqrt3 * ab.y, -0.5 * ab.x - 0.5 * kSqrt3 * ab.y};
}

/// Stator (αβ) → rotor (dq) at angle θ: e^{−jθ}·v.
inline Vec2 park(Vec2 ab, double theta) { return rotate(ab, -theta); }
/// Rotor (dq) → stator (αβ) at angle θ: e^{jθ}·v.
inline Vec2 inverse_park(Vec2 dq, double theta) { return rotate(dq, theta); }

/// Angle wrapped to [0, 2π).
inline double wrap_2pi(double a) {
  double w = std::fmod(a, 2.0 * kPi);
  if (w < 0.0) w += 2.0 * kPi;
  return w;
}

}  // namespace indep
