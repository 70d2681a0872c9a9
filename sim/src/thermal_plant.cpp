#include "rpem/sim/thermal_plant.hpp"

#include <Eigen/LU>
#include <cassert>

namespace rpem::sim {
namespace {

/// A turbulent air gap's Nusselt number grows as Re^0.8, Re ∝ the rotor's surface speed.
constexpr double kGapReynoldsExponent = 0.8;

}  // namespace

ThermalPlant::ThermalPlant(const ThermalPlantConfig& config, const core::PerUnitBase& base) : config_(config), base_(base) {
  assert(config.winding_J_K > 0.0 && config.iron_J_K > 0.0 && config.magnet_J_K > 0.0);
  assert(config.winding_iron_W_K > 0.0 && config.iron_coolant_W_K > 0.0 && config.gap_W_K > 0.0);
  assert(config.magnet_coolant_W_K >= 0.0 && config.gap_speed_gain >= 0.0);
  for (std::size_t n = 0; n < 3; ++n) t_C_(static_cast<Eigen::Index>(n)) = config.start_temperature_C(n);
}

ThermalLosses ThermalPlant::losses(const core::Vec2& i_A, const core::Vec2& psi_Wb, double omega_el_rad_s,
                                   double r_s_Ohm) const noexcept {
  const double f = std::abs(base_.speed_pu(omega_el_rad_s));  // f/f_b
  const double b = base_.flux_pu(psi_Wb.norm());              // |ψ|/ψ_b, the stator yoke's flux density
  const double i = base_.current_pu(i_A.norm());              // |i|/I_b
  ThermalLosses p;
  p.copper_W = 1.5 * r_s_Ohm * i_A.squaredNorm();
  p.iron_W = config_.hysteresis_W * f * std::pow(b, config_.steinmetz_beta) + config_.eddy_W * f * f * b * b;
  p.magnet_W = config_.magnet_eddy_W * f * f * i * i;
  return p;
}

double ThermalPlant::gap_conductance_W_K(double omega_el_rad_s) const noexcept {
  const double f = std::abs(base_.speed_pu(omega_el_rad_s));
  return config_.gap_W_K * (1.0 + config_.gap_speed_gain * std::pow(f, kGapReynoldsExponent));
}

void ThermalPlant::step(const ThermalLosses& losses, double omega_el_rad_s, double dt_s) noexcept {
  const double g_ws = config_.winding_iron_W_K;
  const double g_gap = gap_conductance_W_K(omega_el_rad_s);
  const double g_sc = config_.iron_coolant_W_K;
  const double g_mc = config_.magnet_coolant_W_K;
  // C·dT/dt = −G·T + q: G the conductance matrix (coolant's conductances on the diagonal), q the losses and
  // the coolant's inflow. Trapezoidal: (C + h/2·G)·T⁺ = (C − h/2·G)·T + h·q.
  Eigen::Matrix3d g;
  g << g_ws, -g_ws, 0.0,                   //
      -g_ws, g_ws + g_sc + g_gap, -g_gap,  //
      0.0, -g_gap, g_gap + g_mc;
  const Eigen::Vector3d c(config_.winding_J_K, config_.iron_J_K, config_.magnet_J_K);
  const Eigen::Vector3d q(losses.copper_W, losses.iron_W + g_sc * config_.coolant_C,
                          losses.magnet_W + g_mc * config_.coolant_C);
  const Eigen::Matrix3d lhs = Eigen::Matrix3d(c.asDiagonal()) + 0.5 * dt_s * g;
  const Eigen::Vector3d rhs = c.cwiseProduct(t_C_) - 0.5 * dt_s * (g * t_C_) + dt_s * q;
  t_C_ = lhs.partialPivLu().solve(rhs);
}

double ThermalPlant::stored_heat_J() const noexcept {
  const Eigen::Vector3d c(config_.winding_J_K, config_.iron_J_K, config_.magnet_J_K);
  return c.dot(t_C_ - Eigen::Vector3d::Constant(config_.coolant_C));
}

double ThermalPlant::heat_to_coolant_W() const noexcept {
  return config_.iron_coolant_W_K * (iron_C() - config_.coolant_C) +
         config_.magnet_coolant_W_K * (magnet_C() - config_.coolant_C);
}

}  // namespace rpem::sim
