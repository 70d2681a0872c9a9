#pragma once
// The plant's trajectory while the inverter holds one stator-frame voltage, for a flux map
// (docs/derivations.md §10): dψ/dt = u_dq(t) − R_s·i_s(ψ) − ω·J·ψ has no closed form, so it is
// integrated with the Bogacki–Shampine 3(2) pair (FSAL, three evaluations a step) under local error
// control — each accepted step's error estimate is within `tolerance` × (ψ_m + |ψ|) in each axis —
// and cubic Hermite interpolation between the accepted steps for the search for zero crossings.
// Each evaluation inverts the map for the current (Newton, Magnetics::current).

#include <array>
#include <cstdint>

#include "rpem/sim/plant.hpp"

namespace rpem::sim {

class MapFlow {
 public:
  /// Accepted steps kept per interval; an interval that needs more ends early (reach_s()).
  static constexpr int kMaxSteps = 32;

  explicit MapFlow(double tolerance) noexcept : tolerance_(tolerance) {}

  /// Takes the period's speed from the plant (constant over the period).
  void prepare(const PmsmPlant& plant) noexcept;

  /// Integrates from the plant's present state with the stator-frame voltage u_ab held for at most
  /// h_max_s; reach_s() says how far it got.
  void start(const PmsmPlant& plant, const core::Vec2& u_ab_V, double h_max_s) noexcept;
  [[nodiscard]] double reach_s() const noexcept { return nodes_[static_cast<std::size_t>(count_)].t_s; }

  /// The phase currents and their rates t after the start (0 ≤ t ≤ reach_s()).
  [[nodiscard]] PhaseCurrents phases(double t_s) const noexcept;
  /// Moves the plant to t after the start.
  void commit(PmsmPlant& plant, double t_s) const noexcept;

  [[nodiscard]] std::int64_t accepted_steps() const noexcept { return accepted_; }
  [[nodiscard]] std::int64_t rejected_steps() const noexcept { return rejected_; }

 private:
  /// The solution at an accepted step's end: time, flux, its rate and the magnetising current.
  struct Node {
    double t_s = 0.0;
    core::Vec2 psi_Wb = core::Vec2::Zero();
    core::Vec2 rate_V = core::Vec2::Zero();
    core::Vec2 i_flux_A = core::Vec2::Zero();
  };
  /// dψ/dt at t after the start; i_flux: in the magnetising current's guess, out its value.
  [[nodiscard]] core::Vec2 rate(double t_s, const core::Vec2& psi, core::Vec2& i_flux) const noexcept;
  /// Flux, its rate and the magnetising current t after the start (Hermite between nodes).
  [[nodiscard]] Node at(double t_s) const noexcept;

  double tolerance_;
  const PmsmPlant* plant_ = nullptr;
  double omega_ = 0.0;
  double h_next_s_ = 1e-6;  ///< the step the controller proposes next (kept across intervals)
  core::Rotation r0_;
  core::Vec2 u_ab_V_ = core::Vec2::Zero();
  std::array<Node, kMaxSteps + 1> nodes_{};
  int count_ = 0;
  std::int64_t accepted_ = 0, rejected_ = 0;
};

}  // namespace rpem::sim
