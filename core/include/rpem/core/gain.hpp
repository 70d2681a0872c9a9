#pragma once
// Estimation-gain algorithms of the Ψᵀ-based RPEM (Section III-D): SGA, GNA and PhyInt.
// Each returns the gain matrix L (rows: ψ̂m, r̂s; columns: ε_d, ε_q) for θ̂[k] = θ̂[k−1] + L·ε
// (eq_RPEM_intro). `gradient` is Ψᵀ = dî/dθ̂ (rows: î_d, î_q; columns: ψ̂m, r̂s), so Ψ = gradientᵀ.
// Gain sequences are per nominal sample and per parameter, as in tab_psimgains.

#include <algorithm>
#include <cstdint>

#include "rpem/core/machine.hpp"
#include "rpem/core/types.hpp"

namespace rpem::core {

enum class Algorithm : std::uint8_t { kSga = 0, kGna = 1, kPhyInt = 2 };

/// γ_0 of tab_psimgains for one algorithm: [ψ̂m, r̂s] each.
struct GainSequences {
  Vec2 hessian = Vec2::Zero();  ///< γ_0,rk — the Hessian's forgetting factor
  Vec2 gain = Vec2::Zero();     ///< γ_0,Lk — the step size of the parameter update
};

/// Minimum denominators that keep L bounded where the data carry no information (Section III-D).
struct GainFloors {
  double sga_hessian_min_pu = 0.0;         ///< r[k] is used as max(r[k], this)
  double gna_determinant_min_pu = 0.0;     ///< below this |R|, R⁻¹ is replaced by the Moore–Penrose inverse
  double gna_eigenvalue_min_pu = 0.0;      ///< eigenvalues of R at or below this count as zero in R⁺
  double phyint_denominator_min_pu = 0.0;  ///< |−r̂s·î_d − n·x̂_q·î_q| and |−r̂s·î_q + n·x̂_d·î_d| floor
};

namespace gain_flag {
inline constexpr std::uint8_t kFloored = 1U << 0;        ///< a denominator floor was applied
inline constexpr std::uint8_t kPseudoInverse = 1U << 1;  ///< GNA used R⁺ instead of R⁻¹
}  // namespace gain_flag

struct GainOutput {
  Mat2 gain = Mat2::Zero();
  std::uint8_t flags = 0;
};

/// SGA's gain as one factor per parameter, L = diag(scale)·Ψ: row j of L is scale_j·Ψ_jᵀ.
struct SgaScale {
  Vec2 scale = Vec2::Zero();  ///< γ_L,j / max(r_j[k], r_min)
  std::uint8_t flags = 0;
};

/// SGA (eq:SGA_full, eq:SGAHessian), one scalar Hessian per parameter:
///   r_j[k] = r_j[k−1] + γ_r,j·(tr{Ψ·Ψᵀ} − r_j[k−1]),   L_j = γ_L,j · Ψ_j / max(r_j[k], r_min)
/// Inline: it is on the estimator's per-sample path, which forms L·ε as scale ⊙ (Ψ·ε) (one product after
/// the division) rather than through L.
[[nodiscard]] inline SgaScale sga_scale(const Mat2& gradient, const Vec2& gamma_hessian, const Vec2& gamma_gain,
                                        const GainFloors& floors, Vec2& r) noexcept {
  const double trace = gradient.squaredNorm();  // tr{Ψ·Ψᵀ}, eq:traceSGAHessian
  r += gamma_hessian.cwiseProduct(Vec2(trace, trace) - r);
  const double floor = floors.sga_hessian_min_pu;
  return {gamma_gain.cwiseQuotient(Vec2(std::max(r[0], floor), std::max(r[1], floor))),
          std::min(r[0], r[1]) < floor ? gain_flag::kFloored : std::uint8_t{0}};
}

/// L = diag(scale)·Ψ for Ψᵀ = `gradient`. Built a column at a time: Mat2 is column-major, and element-wise
/// stores would stall the caller's whole-column loads (store forwarding).
[[nodiscard]] inline Mat2 sga_matrix(const Vec2& scale, const Mat2& gradient) noexcept {
  Mat2 l;
  l.col(0) = scale.cwiseProduct(gradient.row(0).transpose());
  l.col(1) = scale.cwiseProduct(gradient.row(1).transpose());
  return l;
}

/// The SGA gain matrix L with its flags (sga_scale() and sga_matrix()).
[[nodiscard]] inline GainOutput sga_gain(const Mat2& gradient, const Vec2& gamma_hessian, const Vec2& gamma_gain,
                                         const GainFloors& floors, Vec2& r) noexcept {
  const SgaScale s = sga_scale(gradient, gamma_hessian, gamma_gain, floors, r);
  return {sga_matrix(s.scale, gradient), s.flags};
}

/// gna_gain's `only` where the step is the joint one.
inline constexpr int kBothParameters = -1;

/// GNA (eq:GNA_full … eq:GNA_GainElements):
///   R[k] = R[k−1] + γ_r·(Ψ·Ψᵀ − R[k−1]),   L = diag(γ_L)·R⁻¹·Ψ,
/// with R⁻¹ from eq:InverseR, or R⁺ (Moore–Penrose) when |R| < floor. γ_r is one scalar, so R stays a
/// convex combination of positive semi-definite matrices; the estimator picks the γ_r of the parameter
/// the scheduler lets adapt (tab_psimgains lists one per estimation case; docs/derivations.md).
/// With `only` = j (0: ψ̂m, 1: r̂s) the Newton step of parameter j alone, the other held: L_j = γ_L,j·Ψ_j/R_jj
/// (R_jj at or below the eigenvalue floor: no step, flagged as R⁺), the other row 0 — what a steady-state sample
/// takes where the schedule lets one parameter adapt (docs/derivations.md §5, "One parameter of a window").
[[nodiscard]] GainOutput gna_gain(const Mat2& gradient, double gamma_hessian, const Vec2& gamma_gain,
                                  const GainFloors& floors, Mat2& hessian, int only = kBothParameters) noexcept;

/// PhyInt (eq:PhyInterPRet, eq:PhyInterPRet_Rs), from the steady-state prediction error:
///   L_11 = −γ_ψ·x̂_d,  L_12 = 0
///   L_2j = γ_r·D / (m·den_j) over the m ∈ {1, 2} components with |den_j| ≥ floor, where
///   den_d = −r̂s·î_d − n·x̂_q·î_q,  den_q = −r̂s·î_q + n·x̂_d·î_d,  D = r̂s² + n²·x̂_d·x̂_q.
/// The 1/m weight makes L·ε = γ·δr̂s in steady state; the printed form (m = 1) gives 2γ·δr̂s when
/// both components are used (erratum E3, docs/derivations.md).
[[nodiscard]] GainOutput phyint_gain(const MachinePu& model, double n_pu, const Vec2& i_hat_pu, const Vec2& gamma_gain,
                                     const GainFloors& floors) noexcept;

/// Moore–Penrose pseudo-inverse of a symmetric 2×2 matrix, closed form; eigenvalues ≤ `eigenvalue_min`
/// are treated as zero.
[[nodiscard]] Mat2 symmetric_pseudo_inverse(const Mat2& r, double eigenvalue_min) noexcept;

}  // namespace rpem::core
