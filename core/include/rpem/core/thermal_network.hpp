#pragma once
// The machine's lumped-parameter thermal network (LPTN; docs/derivations.md §14): 2–4 nodes — at least the
// winding and the magnet — joined by thermal conductances, each node tied to the coolant by another, with
// a heat capacity each, heated by the losses:
//
//   C_i·dT_i/dt = P_i − Σ_j G_ij·(T_i − T_j) − G_i0(ω)·(T_i − T_coolant)                 (eq. 14.1)
//   G(ω) = G + G_ω·√(|ω|/ω_b)   a conductance by convection grows with the rotor's speed   (eq. 14.1b)
//                               (to the coolant G_i0, or across the air gap G_ij)
//   P_winding  += s_cu·(3/2)·R_s(T_winding)·|i_dq|²   copper, R_s's own law (core/thermal.hpp)  (eq. 14.2)
//   P_i        += Σ_forms k_form,i·basis_form(ω, ψ_s, |i|)     iron and magnet losses         (eq. 14.3)
//
// The loss forms are a catalogue (thermal_network.cpp, kLossForms): hysteresis ∝ f·B², eddy currents
// ∝ f²·B² (B ∝ |ψ_s|, the stator flux linkage), and magnet eddy currents from the armature's harmonics
// ∝ f²·|i|², each 1 at the loss base (ω_b, ψ_b, i_b) so that k is the loss in watts there.
// Since R_s is linear in T_winding the network is linear in T: dT/dt = A·T + u + C⁻¹·d with A and u
// constant over a step whose inputs are held (their means), so the step is exact (zero-order hold), also
// for a heat d [W] held over it (the filter's disturbance, thermal_filter.hpp):
//   T⁺ = Φ·T + γ + Γ_d·d,   Φ = e^{A·Δt},  γ = Δt·φ₁(A·Δt)·u,  Γ_d = Δt·φ₁(A·Δt)·C⁻¹          (eq. 14.4)
// Nodes past `nodes` are unused: their rows are zero, they keep their value. Real-time safe.

#include <array>
#include <cstdint>
#include <string_view>

#include "rpem/core/thermal.hpp"
#include "rpem/core/types.hpp"

namespace rpem::core {

inline constexpr int kMaxThermalNodes = 4;
using ThermalVec = Eigen::Matrix<double, kMaxThermalNodes, 1>;
using ThermalMat = Eigen::Matrix<double, kMaxThermalNodes, kMaxThermalNodes>;

/// The loss forms of eq. 14.3 (stable numbers: they index thermal.yaml's `losses` and the tables).
enum class LossForm : std::uint8_t { kIronHysteresis = 0, kIronEddy = 1, kMagnetEddy = 2 };
inline constexpr int kLossForms = 3;

/// Where the loss forms equal 1: the electrical speed, the stator flux linkage and the current there.
struct LossBase {
  double omega_el_rad_s = 0.0;
  double psi_Wb = 0.0;
  double current_A = 0.0;
};

/// The operating point of a loss form, relative to the loss base.
struct LossPoint {
  double f_rel = 0.0;    ///< |ω|/ω_b
  double psi_rel = 0.0;  ///< |ψ_s|/ψ_b
  double i_rel = 0.0;    ///< |i|/i_b
};

/// One row of the loss-form catalogue.
struct LossFormRow {
  LossForm form;
  std::string_view name;      ///< as in thermal.yaml
  std::string_view equation;  ///< for reports
  double (*basis)(const LossPoint&) noexcept;
};
[[nodiscard]] const std::array<LossFormRow, kLossForms>& loss_forms() noexcept;

struct ThermalNetwork {
  int nodes = 2;    ///< in use, 2..kMaxThermalNodes
  int winding = 0;  ///< the node the copper loss heats and R_s's temperature is
  int magnet = 1;   ///< the node ψm's temperature is
  ThermalVec capacitance_J_per_K = ThermalVec::Ones();
  ThermalVec to_coolant_W_per_K = ThermalVec::Zero();
  /// G_i0,ω: the part of G_i0 that grows with speed as √(|ω|/ω_b), its value at the loss base's speed (eq. 14.1b).
  ThermalVec to_coolant_at_base_speed_W_per_K = ThermalVec::Zero();
  ThermalMat between_W_per_K = ThermalMat::Zero();  ///< symmetric, zero diagonal
  /// G_ij,ω: the part of G_ij that grows with speed as √(|ω|/ω_b), at the loss base's speed (eq. 14.1b).
  ThermalMat between_at_base_speed_W_per_K = ThermalMat::Zero();  ///< symmetric, zero diagonal
  /// k per form (row) and node (column): the loss at the loss base [W].
  Eigen::Matrix<double, kLossForms, kMaxThermalNodes> loss_at_base_W =
      Eigen::Matrix<double, kLossForms, kMaxThermalNodes>::Zero();
  DriftLaw copper;  ///< R_s(T_winding) [Ω] (value_ref set)
  /// s_cu: the copper loss relative to (3/2)·R_s·|i|² (AC resistance, stray load losses that go with i²); 1 nominal.
  double copper_scale = 1.0;
  LossBase base;
};

/// The inputs of one step, held over it (their means over the step): eq. 14.4's zero-order hold.
struct ThermalLoad {
  double dt_s = 0.0;
  double current_sq_A2 = 0.0;              ///< mean of i_d² + i_q²
  std::array<double, kLossForms> basis{};  ///< mean of each form's basis
  double convection_basis = 0.0;           ///< mean of √(|ω|/ω_b): eq. 14.1b's speed term
  double coolant_C = 0.0;
};

/// Accumulates the loads of the samples of one step.
class LossAccumulator {
 public:
  /// One sample lasting dt_s: its current, electrical speed and stator flux linkage (rotor frame).
  void add(const LossBase& base, double dt_s, const Vec2& i_dq_A, double omega_el_rad_s, const Vec2& psi_dq_Wb,
           double coolant_C) noexcept;
  [[nodiscard]] double duration_s() const noexcept { return dt_s_; }
  /// The step's means (dt_s the accumulated time); starts over.
  [[nodiscard]] ThermalLoad take() noexcept;

 private:
  double dt_s_ = 0.0, current_sq_ = 0.0, convection_ = 0.0, coolant_ = 0.0;
  std::array<double, kLossForms> basis_{};
};

/// The basis of each form at an operating point.
[[nodiscard]] std::array<double, kLossForms> loss_basis(const LossBase& base, const Vec2& i_dq_A, double omega_el_rad_s,
                                                        const Vec2& psi_dq_Wb) noexcept;

/// dT/dt = A·T + u over a step with load `l` (eq. 14.1–14.3).
struct ThermalRates {
  ThermalMat a = ThermalMat::Zero();
  ThermalVec u = ThermalVec::Zero();
  ThermalVec coolant_per_s = ThermalVec::Zero();  ///< ∂(dT_i/dt)/∂T_coolant = G_i0(ω)/C_i: u's coolant part per kelvin
};
[[nodiscard]] ThermalRates thermal_rates(const ThermalNetwork& n, const ThermalLoad& l) noexcept;

/// The node losses [W] at temperatures T under load `l` (copper at T_winding).
[[nodiscard]] ThermalVec node_losses_W(const ThermalNetwork& n, const ThermalLoad& l, const ThermalVec& t_C) noexcept;

/// T⁺ = Φ·T + γ + Γ_d·d over l.dt_s, exact for the held load and heat d (eq. 14.4).
struct ThermalTransition {
  ThermalMat phi = ThermalMat::Identity();
  ThermalVec gamma = ThermalVec::Zero();
  ThermalMat gamma_d = ThermalMat::Zero();  ///< [K/W]
};
/// `r`: the step's rates (thermal_rates of its load), for a caller that needs them besides (ThermalFusion forms them
/// once a step for the transition, the observations and the readout).
[[nodiscard]] ThermalTransition thermal_transition(const ThermalNetwork& n, const ThermalRates& r, double dt_s) noexcept;
[[nodiscard]] ThermalTransition thermal_transition(const ThermalNetwork& n, const ThermalLoad& l) noexcept;

/// The steady state T_∞ = −A⁻¹·u of a load held for ever (the nodes in use; unused ones at the coolant).
[[nodiscard]] ThermalVec thermal_steady_state(const ThermalNetwork& n, const ThermalLoad& l) noexcept;

}  // namespace rpem::core
