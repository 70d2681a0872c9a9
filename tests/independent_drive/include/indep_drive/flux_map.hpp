#pragma once
// Measured flux-linkage maps (data/beckhoff-am8141-flux-maps, data/reforce-pmsm-flux-map): read, fitted
// with a co-energy polynomial, and scaled to a machine (README "Saturation").
#include <string>
#include <vector>

#include "indep_drive/flux_model.hpp"
#include "indep_drive/machine_config.hpp"

namespace indep {

struct FluxMapPoint {
  double i_d_A = 0, i_q_A = 0, psi_d_Wb = 0, psi_q_Wb = 0;
};

struct FluxMapData {
  std::string path;
  std::vector<FluxMapPoint> points;
};

/// Reads a map CSV by its column names (`i_d_A,i_q_A,psi_d_Vs,psi_q_Vs` or gym-electric-motor's
/// `i_d_grid_k,i_q_grid_k,Psi_d_map,Psi_q_map`); rows with NaN are skipped. Throws std::runtime_error
/// naming file and line.
FluxMapData read_flux_map(const std::string& path);

/// A least-squares fit of the map to ψ = ∇W', W' = I_m·(ψ0·x_d + Σ a_mn·x_d^m·x_q^n), x = i/I_m, over
/// 2 ≤ m+n ≤ degree with n even (ψ_d even and ψ_q odd in i_q), I_m the largest |i_q| of the map.
struct FluxMapFit {
  double axis_rotation_rad = 0;  // δ: the map's frame turned by −δ so that ψ_q = 0 at its smallest current
  double current_scale_A = 0;    // I_m
  double psi0_Wb = 0;            // ψ_d at zero current
  std::vector<PolyTerm> terms;   // a_mn, including (2,0) and (0,2)
  double rms_residual_Wb = 0;    // over both ψ_d and ψ_q of every point
  double max_residual_Wb = 0;
  double max_abs_x_d = 0, max_abs_x_q = 0;  // extent of the data in x
  [[nodiscard]] double l_d0_H() const;      // 2·a_20 / I_m
  [[nodiscard]] double l_q0_H() const;      // 2·a_02 / I_m
};

FluxMapFit fit_flux_map(const FluxMapData& map, int degree = 4);

/// Which parts of the fitted shape the machine gets.
struct SaturationParts {
  bool ld = false;     // pure-d terms (n = 0, m ≥ 3): L_d against i_d
  bool lq = false;     // pure-q terms (m = 0, n ≥ 4): L_q against i_q
  bool cross = false;  // mixed terms (m ≥ 1, n ≥ 2): ψ_d against i_q, L_q against i_d
  double depth = 1.0;  // multiplies every term above quadratic (1 = the map's own saturation)
};

/// The map's shape on a machine with small-signal inductances L_d, L_q: the map's current I_m maps to
/// `full_scale_current_A`, pure-d terms scale by k_d = L_d·I_b/(2·a_20), pure-q by k_q = L_q·I_b/(2·a_02),
/// mixed by √(k_d·k_q) (keeps the normalised coupling L_dq/√(L_dd·L_qq) of the map); all by parts.depth.
FluxModel scale_flux_map(const FluxMapFit& fit, const MachineParams& machine, double full_scale_current_A,
                         SaturationParts parts);

}  // namespace indep
