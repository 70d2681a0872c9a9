#pragma once
// R_s adaptation at standstill, where the ψm gradients vanish and both SGA and GNA reduce to one scalar
// recursion (docs/derivations.md, erratum E5; docs/reproduction.md, "Every difference"). With the
// current held at its reference by the controller (u = r_s·i) and x = r̂s/r_s − 1:
//   î = i/(1 + x),   ε = i − î = i·x/(1 + x),   Ψ = dî/dr̂s = −(i/r_s)/(1 + x)²
//   R[k] = (1 − γ_r)·R[k−1] + γ_r·Ψ[k]²            (SGA: tr{ΨΨᵀ} = Ψ² here; GNA: R = ΨΨᵀ's r_s entry)
//   x[k+1] = x[k] + γ_L·Ψ[k]·ε[k] / (r_s·R[k])      (L = γ_L·R⁻¹·Ψ, eq:SGA_full / eq:GNA_full)
// In units of the settled Hessian at the true value, (i/r_s)² = 1, the recursion depends only on γ_r,
// γ_L, the initial error and R[0]/(i/r_s)². R[0] → 0 gives the fastest start there is: the bound.

#include <optional>

namespace rpem::analysis {

struct StandstillRs {
  double gamma_r = 0.0;  ///< γ_0,rk of the R_s sequence (per sample)
  double gamma_L = 0.0;  ///< γ_0,Lk of the R_s sequence (per sample)
  double sample_period_s = 125e-6;
  double hessian0_rel = 0.0;  ///< R[0] / (i/r_s)²; 0: the fastest start (the bound)
};

/// Time from the start until |r̂s/r_s − 1| ≤ band, from r̂s/r_s − 1 = initial_error; empty if that takes
/// longer than `horizon_s` or the recursion leaves (−1, ∞).
[[nodiscard]] std::optional<double> standstill_rs_time_s(const StandstillRs& m, double initial_error, double band = 0.01,
                                                         double horizon_s = 1000.0);

/// The same linearised about the true value (x ≪ 1, Ψ constant): e[k+1] = (1 − g_k)·e[k] with
/// g_k = γ_L / (1 − (1 − γ_r)^k), the largest rate any R[0] ⪰ 0 allows. This is the bound as first derived
/// (13.9 s from 8 % with tab_psimgains' GNA column); it ignores that Ψ and ε grow as r̂s falls.
[[nodiscard]] std::optional<double> linearised_rs_bound_s(double gamma_r, double gamma_L, double sample_period_s,
                                                          double initial_error, double band = 0.01,
                                                          double horizon_s = 1000.0);

/// The initial error from which the recursion takes exactly `time_s` (bisection over (band, 1]); empty if
/// no error in that range takes that long.
[[nodiscard]] std::optional<double> standstill_rs_initial_error_for(const StandstillRs& m, double time_s,
                                                                    double band = 0.01);

/// r̂s/r_s − 1 after `time_s` from `initial_error`: the band within which the estimate is at that time.
[[nodiscard]] double standstill_rs_error_after(const StandstillRs& m, double initial_error, double time_s);

}  // namespace rpem::analysis
