#pragma once
// Speed-dependent convection (README.md, "Convection").
//   Air gap (Taylor-Couette flow between a rotating and a fixed cylinder): Ta = Re·√(g/R_r), Re = Ω·R_r·g/ν;
//   Nu = 2 (laminar: conduction across the gap), 0.202·Ta^0.63·Pr^0.27 (Taylor vortices),
//   0.386·Ta^0.5·Pr^0.27 (turbulent) — the Becker-Kaye correlations as used for machines (Staton and
//   Cavagnino 2008; Howey, Childs and Holmes 2012) — taken continuous here as max(2, min(vortex, turbulent)),
//   which moves the published regime limits (Ta 41, 100) to 44.3 and 146. h = Nu·k/(2g), area π·D_r·L.
//   End space: h = k1·(1 + k2·v^k3), v the rotor's peripheral speed (the form of Staton and Cavagnino 2008),
//   between a massless end-space air node and three surfaces: the end windings, the rotor's end faces and
//   the end caps (at the coolant). The air node eliminated (star-delta) gives three conductances.
#include "indep_thermal/parameters.hpp"

namespace indep_thermal {

/// Modified Taylor number of the air gap at mechanical speed ω_m.
double taylor_number(const Parameters& p, double omega_mech_rad_s);
/// Air-gap Nusselt number (hydraulic diameter 2g) for a Taylor number and Prandtl number.
double airgap_nusselt(double taylor, double prandtl);
/// Rotor-to-stator-iron conductance through the air gap [W/K].
double airgap_conductance_W_K(const Parameters& p, double omega_mech_rad_s);

/// End-space heat transfer coefficient at peripheral speed v [W/(m²·K)].
double endspace_h_W_m2K(const Parameters& p, double v_m_s);

struct EndSpaceAreas {
  double winding_m2 = 0.0;  // both end windings, inner and outer faces: 2π·(D_r + D_s)·l_ew
  double rotor_m2 = 0.0;    // both rotor end faces: 2·π/4·D_r²
  double caps_m2 = 0.0;     // both end caps' inner faces: 2·π/4·D_s²
};
EndSpaceAreas endspace_areas(const Parameters& p);

/// The end-space star (air node) turned into a delta [W/K].
struct EndSpaceConductances {
  double winding_rotor = 0.0;
  double winding_coolant = 0.0;
  double rotor_coolant = 0.0;
};
EndSpaceConductances endspace_conductances(const Parameters& p, double omega_mech_rad_s);

}  // namespace indep_thermal
