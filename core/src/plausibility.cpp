#include "rpem/core/plausibility.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {
namespace {

/// |x| ≤ limit, NaN passing.
bool below(double x, double limit) noexcept { return !(std::abs(x) > limit); }

/// Every |x_k| ≤ limit, NaN passing (Eigen's maxCoeff leaves NaN's order unspecified).
template <typename Vector>
bool all_below(const Vector& v, double limit) noexcept {
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (!below(v[k], limit)) return false;
  }
  return true;
}

bool temperature_within(double t_C, const PlausibleMagnitudes& m) noexcept {
  return !(t_C < m.temperature_min_C) && !(t_C > m.temperature_max_C);
}

}  // namespace

PlausibleMagnitudes machine_plausible(const RatedData& rated) noexcept {
  const PerUnitBase base = PerUnitBase::from_rated(rated);
  PlausibleMagnitudes m;
  m.current_A = std::min(m.current_A, kRatedMultipleLimit * base.current_A);
  m.voltage_V = std::min(m.voltage_V, kRatedMultipleLimit * base.voltage_V);
  m.speed_rad_s = std::min(m.speed_rad_s, kRatedMultipleLimit * base.omega_el_rad_s);
  return m;
}

bool within(const DriveSample& s, const PlausibleMagnitudes& m) noexcept {
  return below(s.theta_el_rad, m.angle_rad) && below(s.omega_el_rad_s, m.speed_rad_s) && below(s.u_dc_V, m.dc_link_V) &&
         all_below(s.u_V, m.voltage_V) && all_below(s.i_A, m.current_A) && temperature_within(s.t_winding_C, m) &&
         temperature_within(s.t_coolant_C, m);
}

bool within(const AveragedSample& s, const PlausibleMagnitudes& m) noexcept {
  return below(s.omega_el_rad_s, m.speed_rad_s) && below(s.omega_el_error_rad_s, m.speed_rad_s) &&
         below(s.omega_el_error_noise_rad_s, m.speed_rad_s) && below(s.omega_counted_el_rad_s, m.speed_rad_s) &&
         below(s.u_dc_V, m.dc_link_V) && all_below(s.u_dq_V, m.voltage_V) && all_below(s.i_dq_A, m.current_A) &&
         temperature_within(s.t_winding_C, m) && temperature_within(s.t_magnet_C, m) && temperature_within(s.t_drive_C, m) &&
         temperature_within(s.t_coolant_C, m);
}

}  // namespace rpem::core
