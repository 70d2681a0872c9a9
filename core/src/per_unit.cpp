#include "rpem/core/per_unit.hpp"

#include <cmath>

#include "rpem/core/units.hpp"

namespace rpem::core {

PerUnitBase PerUnitBase::from_rated(const RatedData& rated) noexcept {
  PerUnitBase b;
  b.pole_pairs = rated.pole_pairs;
  b.voltage_V = std::sqrt(2.0) * rated.voltage_ll_rms_V / kSqrt3;
  b.current_A = std::sqrt(2.0) * rated.current_rms_A;
  b.omega_el_rad_s = rpm_to_rad_s(rated.pole_pairs * rated.speed_rpm);
  b.omega_mech_rad_s = b.omega_el_rad_s / rated.pole_pairs;
  b.flux_Wb = b.voltage_V / b.omega_el_rad_s;
  b.impedance_Ohm = b.voltage_V / b.current_A;
  b.inductance_H = b.impedance_Ohm / b.omega_el_rad_s;
  b.torque_Nm = 1.5 * rated.pole_pairs * b.flux_Wb * b.current_A;
  return b;
}

double PerUnitBase::mech_speed_rpm_to_pu(double n_rpm) const noexcept { return rpm_to_rad_s(n_rpm) / omega_mech_rad_s; }

double PerUnitBase::mech_speed_rpm_of(double n_pu) const noexcept { return rad_s_to_rpm(n_pu * omega_mech_rad_s); }

}  // namespace rpem::core
