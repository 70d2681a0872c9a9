#pragma once
// Whether a thermal network settles under a load (docs/derivations.md §14, eq. 14.27): the condition a network must
// meet at the machine's rated point to be accepted (io/thermal_config.hpp), since a rated current is one the machine
// carries for ever.

#include "rpem/core/thermal_network.hpp"

namespace rpem::core {

/// Whether every solution under load `l` settles to its steady state: −C·A = L(ω) + diag(G_i0(ω)) − K_cu,
/// symmetric, positive definite (eq. 14.27). False where the copper loss's rise with the winding's temperature
/// outgrows what the network conducts to the coolant (a winding that runs away) or no node reaches the coolant.
[[nodiscard]] bool thermal_settles(const ThermalNetwork& n, const ThermalLoad& l) noexcept;

/// The winding's conductance to the coolant through the whole network under load `l`, 1/(M⁻¹)_ww with
/// M = L(ω) + diag(G_i0(ω)) the conductance matrix (directly and through every other node; on two nodes
/// G_w0 + G_wm·G_m0/(G_wm + G_m0)): the network settles exactly while the copper loss's rise K is below it (eq. 14.27,
/// by the Schur complement of M − K·e_w·e_wᵀ). 0 where no node reaches the coolant [W/K].
[[nodiscard]] double winding_conductance_to_coolant_W_per_K(const ThermalNetwork& n, const ThermalLoad& l) noexcept;

}  // namespace rpem::core
