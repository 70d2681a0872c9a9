#pragma once
// The machine's current → flux-linkage relation in the rotor frame, from a co-energy potential
// (README "Saturation"):
//
//   W'(i) = ψm·i_d + ½·L_d·i_d² + ½·L_q·i_q² + I_b · Σ b_mn · x_d^m · x_q^n,   x = i / I_b
//   ψ_d = ∂W'/∂i_d,  ψ_q = ∂W'/∂i_q,   L_diff = ∂²W'/∂i²  (symmetric: reciprocity holds by construction)
//
// With no terms it is the linear machine ψ_d = ψm + L_d·i_d, ψ_q = L_q·i_q.
#include <vector>

#include "indep_drive/frames.hpp"

namespace indep {

struct PolyTerm {
  int m = 0;        // power of x_d
  int n = 0;        // power of x_q
  double b_Wb = 0;  // coefficient (flux units: ∂/∂x of b·x_d^m·x_q^n is in Wb)
};

struct Inductance2 {
  double dd_H = 0.0, dq_H = 0.0, qq_H = 0.0;  // ∂ψ_d/∂i_d, ∂ψ_d/∂i_q (= ∂ψ_q/∂i_d), ∂ψ_q/∂i_q
};

class FluxModel {
 public:
  FluxModel() = default;
  FluxModel(double l_d_H, double l_q_H, double current_scale_A, std::vector<PolyTerm> terms);

  /// ψ(i) [Wb] for the magnet flux ψm [Wb] (harmonics excluded: see HarmonicFlux).
  [[nodiscard]] Vec2 flux(Vec2 i_A, double psi_m_Wb) const;
  /// ∂ψ/∂i [H].
  [[nodiscard]] Inductance2 inductance(Vec2 i_A) const;
  /// Co-energy W'(i) [J] (per the amplitude-invariant dq frame: the machine's is 1.5× this).
  [[nodiscard]] double coenergy(Vec2 i_A, double psi_m_Wb) const;
  /// Solves ψ(i) = psi for i by Newton's method from `guess` (exact in one step when linear).
  [[nodiscard]] Vec2 current(Vec2 psi_Wb, double psi_m_Wb, Vec2 guess_A) const;

  [[nodiscard]] bool linear() const { return terms_.empty(); }
  [[nodiscard]] double l_d_H() const { return l_d_; }
  [[nodiscard]] double l_q_H() const { return l_q_; }
  [[nodiscard]] double current_scale_A() const { return i_b_; }
  [[nodiscard]] const std::vector<PolyTerm>& terms() const { return terms_; }

 private:
  double l_d_ = 0.0, l_q_ = 0.0, i_b_ = 1.0;
  std::vector<PolyTerm> terms_;
};

}  // namespace indep
