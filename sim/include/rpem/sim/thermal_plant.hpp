#pragma once
// The simulated machine's temperatures from its own losses (`thermal_plant:` in a scenario; docs/scenarios.md,
// "A loss-driven thermal plant"): three nodes — winding w, stator iron s, magnet m — and the coolant c,
//
//   C_w·dT_w/dt = P_cu − G_ws·(T_w − T_s)
//   C_s·dT_s/dt = P_fe + G_ws·(T_w − T_s) − G_sc·(T_s − T_c) − G_gap(ω)·(T_s − T_m)
//   C_m·dT_m/dt = P_pm + G_gap(ω)·(T_s − T_m) − G_mc·(T_m − T_c)
//
// with the copper loss at the plant's own temperature-dependent resistance, P_cu = (3/2)·R_s(T_w)·|i|²;
// Steinmetz's iron loss in the stator, P_fe = P_h·(f/f_b)·(|ψ|/ψ_b)^β + P_e·(f/f_b)²·(|ψ|/ψ_b)²; the magnets'
// eddy loss P_pm = P_pm,b·(f/f_b)²·(|i|/I_b)²; and the air gap's convection growing with speed,
// G_gap(ω) = G_gap,0·(1 + k_gap·(|ω|/ω_b)^0.8) (a turbulent Nusselt number ∝ Re^0.8). These are the simulator's
// forms, not the fit's network (core/thermal_network.hpp: two nodes, other loss forms), so that a fit on a
// simulated log meets a plant it does not contain. Stepped by the trapezoidal rule (A-stable, second order),
// the losses held over each step.

#include <array>
#include <cmath>

#include "rpem/core/per_unit.hpp"
#include "rpem/core/types.hpp"

namespace rpem::sim {

/// The defaults are a plausible 2 kW water-cooled machine (the paper's, tab_machineData): ≈ 0.8 kg of copper,
/// 6 kg of stator iron, 4 kg of rotor; a scenario gives its machine's values (docs/scenarios.md).
struct ThermalPlantConfig {
  bool enabled = false;
  double coolant_C = 25.0;
  double winding_J_K = 800.0, iron_J_K = 2800.0, magnet_J_K = 1800.0;  ///< heat capacities
  double winding_iron_W_K = 8.0;                                       ///< G_ws: through the slot liner
  double iron_coolant_W_K = 6.0;                                       ///< G_sc: the housing's water jacket
  double gap_W_K = 1.5;                                                ///< G_gap,0: across the air gap at standstill
  double gap_speed_gain = 2.0;      ///< k_gap: the air gap's conductance at base speed is (1 + k_gap)·G_gap,0
  double magnet_coolant_W_K = 0.5;  ///< G_mc: through the shaft and bearings
  double hysteresis_W = 40.0;       ///< P_h at base frequency and base flux
  double eddy_W = 25.0;             ///< P_e at base frequency and base flux
  double steinmetz_beta = 1.8;      ///< β
  double magnet_eddy_W = 5.0;       ///< P_pm,b at base frequency and base current
  /// Temperatures at t = 0 (winding, iron, magnet); NaN: the coolant's (a soaked machine).
  std::array<double, 3> start_C{std::nan(""), std::nan(""), std::nan("")};

  /// Node n's temperature at t = 0 (0 winding, 1 iron, 2 magnet).
  [[nodiscard]] double start_temperature_C(std::size_t n) const noexcept {
    return std::isnan(start_C[n]) ? coolant_C : start_C[n];
  }
};

/// The losses at one instant [W].
struct ThermalLosses {
  double copper_W = 0.0, iron_W = 0.0, magnet_W = 0.0;
};

class ThermalPlant {
 public:
  ThermalPlant() = default;
  /// `base`: the machine's per-unit base (ω_b, ψ_b, I_b); the configuration must be valid (positive
  /// capacities and conductances, as the scenario reader checks).
  ThermalPlant(const ThermalPlantConfig& config, const core::PerUnitBase& base);

  /// The losses at stator current i_dq, flux linkage ψ_dq, electrical speed ω and resistance R_s.
  [[nodiscard]] ThermalLosses losses(const core::Vec2& i_A, const core::Vec2& psi_Wb, double omega_el_rad_s,
                                     double r_s_Ohm) const noexcept;
  /// Advances by dt with `losses` held (the trapezoidal rule); ω sets the air gap's conductance.
  void step(const ThermalLosses& losses, double omega_el_rad_s, double dt_s) noexcept;

  [[nodiscard]] double winding_C() const noexcept { return t_C_(0); }
  [[nodiscard]] double iron_C() const noexcept { return t_C_(1); }
  [[nodiscard]] double magnet_C() const noexcept { return t_C_(2); }
  [[nodiscard]] double coolant_C() const noexcept { return config_.coolant_C; }
  /// G_gap(ω) [W/K].
  [[nodiscard]] double gap_conductance_W_K(double omega_el_rad_s) const noexcept;
  /// Heat stored above the coolant, Σ C·(T − T_c) [J] (for energy balances).
  [[nodiscard]] double stored_heat_J() const noexcept;
  /// Heat flowing to the coolant now [W].
  [[nodiscard]] double heat_to_coolant_W() const noexcept;

 private:
  ThermalPlantConfig config_;
  core::PerUnitBase base_;
  Eigen::Vector3d t_C_ = Eigen::Vector3d::Zero();
};

}  // namespace rpem::sim
