#pragma once
// The terms of the network's rates at a load (docs/derivations.md §14, eq. 14.1b, 14.2, 14.4): each conductance at
// the load's speed and the copper loss's rise with the winding's temperature. thermal_rates() assembles A and u from
// them; the check that a network settles at the rating (eq. 14.27, io/src/thermal_config.cpp) names them.

#include "rpem/core/thermal_network.hpp"

namespace rpem::core {

/// G_i0(ω) = G_i0 + G_i0,ω·√(|ω|/ω_b), node i to the coolant at the load's speed (eq. 14.1b) [W/K].
[[nodiscard]] inline double coolant_conductance_W_per_K(const ThermalNetwork& n, const ThermalLoad& l, int i) noexcept {
  return n.to_coolant_W_per_K[i] + n.to_coolant_at_base_speed_W_per_K[i] * l.convection_basis;
}

/// G_ij(ω) = G_ij + G_ij,ω·√(|ω|/ω_b), between nodes i and j at the load's speed (eq. 14.1b) [W/K].
[[nodiscard]] inline double node_conductance_W_per_K(const ThermalNetwork& n, const ThermalLoad& l, int i, int j) noexcept {
  return n.between_W_per_K(i, j) + n.between_at_base_speed_W_per_K(i, j) * l.convection_basis;
}

/// K = s_cu·(3/2)·R_ref·α_cu·|i|²: how much the copper loss grows per kelvin of the winding (eq. 14.2, 14.4) [W/K].
[[nodiscard]] inline double copper_loss_per_K(const ThermalNetwork& n, const ThermalLoad& l) noexcept {
  return n.copper_scale * 1.5 * l.current_sq_A2 * n.copper.value_ref * n.copper.coeff_per_K;
}

}  // namespace rpem::core
