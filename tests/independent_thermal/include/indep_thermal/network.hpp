#pragma once
// The three-node network (README.md, "Network"): nodes winding (w), stator iron (s), rotor with magnets (r);
// the coolant (c) is their boundary. Six links, three of them speed-dependent:
//   w–s  slot liner                 constant
//   s–c  housing and water jacket   constant
//   r–s  air gap                    Taylor-Couette convection, rises with speed
//   w–r, w–c, r–c  end space        convection through the end-space air, rises with speed
//   r–c  shaft and bearings         constant (added to the end-space r–c link)
//   C·dT/dt = P − G·T + g_c·T_c,   G = Laplacian of the internal links + diag(g_c).
#include <Eigen/Dense>

#include "indep_thermal/parameters.hpp"

namespace indep_thermal {

enum Node : int { kWinding = 0, kIron = 1, kRotor = 2 };

struct Conductances {
  double winding_iron = 0.0;
  double iron_coolant = 0.0;
  double airgap = 0.0;           // rotor–iron
  double winding_rotor = 0.0;    // end space
  double winding_coolant = 0.0;  // end space
  double rotor_coolant = 0.0;    // end space + shaft

  /// G: symmetric, positive definite while every link is positive [W/K].
  [[nodiscard]] Eigen::Matrix3d matrix() const;
  /// g_c: each node's links to the coolant [W/K].
  [[nodiscard]] Eigen::Vector3d to_coolant() const;
};

/// The network's links at mechanical speed ω_m.
Conductances conductances(const Parameters& p, double omega_mech_rad_s);

/// Heat capacities C = (C_w, C_s, C_r) [J/K].
Eigen::Vector3d capacities(const Parameters& p);

}  // namespace indep_thermal
