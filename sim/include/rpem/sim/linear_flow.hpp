#pragma once
// The plant's exact trajectory while the inverter holds one stator-frame voltage, for constant
// inductances (docs/derivations.md §10). With the speed constant over the interval the rotor-frame
// flux obeys the linear system
//   dψ/dt = A·ψ + c + u(t),   A = −R_s·K − ω·J,   K = L⁻¹ + (ω/R_fe)·J,   c = R_s·L⁻¹·[ψ_m, 0]ᵀ,
// driven by the held stator voltage as the rotor sees it, u(t) = e^{Ω·t}·u₀ with Ω = −ω·J. This is
// the matrix exponential of the augmented system d/dt [ψ; u; 1] = [A I c; 0 Ω 0; 0 0 0]·[ψ; u; 1],
// which start() sums as the Taylor series at the interval's start,
//   ψ(t) = Σ aₙ·tⁿ,  a₀ = ψ₀,  a₁ = A·ψ₀ + c + u₀,  aₙ = (A·aₙ₋₁ + Ωⁿ⁻¹·u₀/(n−1)!)/n,
// to the order N at which the remainder is below round-off; ψ(t), dψ/dt and so the phase currents are
// then polynomials anywhere inside the interval, which the search for zero crossings evaluates.
// No step size is involved: the solution is exact to round-off.

#include <array>

#include "rpem/sim/plant.hpp"

namespace rpem::sim {

class LinearFlow {
 public:
  /// The highest order of the series; a longer interval is cut at ρ = μ·t = 1 (μ ≥ ‖A‖ + |ω|).
  static constexpr int kMaxOrder = 19;

  /// Takes the period's parameters and speed from the plant (constant over the period).
  void prepare(const PmsmPlant& plant) noexcept;

  /// The trajectory from the plant's present state with the stator-frame voltage u_ab held for at
  /// most h_max_s. reach_s() says how far it extends (h_max_s unless ρ would exceed 1).
  void start(const PmsmPlant& plant, const core::Vec2& u_ab_V, double h_max_s) noexcept;
  [[nodiscard]] double reach_s() const noexcept { return reach_s_; }
  [[nodiscard]] int order() const noexcept { return order_; }

  /// Rotor-frame flux t after the start (0 ≤ t ≤ reach_s()).
  [[nodiscard]] core::Vec2 flux(double t_s) const noexcept;
  /// The phase currents and their rates t after the start.
  [[nodiscard]] PhaseCurrents phases(double t_s) const noexcept;
  /// Moves the plant to t after the start.
  void commit(PmsmPlant& plant, double t_s) const noexcept;

 private:
  [[nodiscard]] core::Vec2 flux_rate(double t_s) const noexcept;

  core::Mat2 a_ = core::Mat2::Zero();      ///< A
  core::Mat2 k_ = core::Mat2::Identity();  ///< K: i_s = K·ψ − k0
  core::Vec2 k0_A_ = core::Vec2::Zero();
  core::Vec2 c_V_ = core::Vec2::Zero();
  double omega_ = 0.0;
  double mu_ = 0.0;  ///< ‖A‖∞ + |ω|, the growth rate that bounds the series' terms

  core::Rotation r0_;
  std::array<core::Vec2, kMaxOrder + 1> coeff_{};
  int order_ = 0;
  double reach_s_ = 0.0;
};

}  // namespace rpem::sim
