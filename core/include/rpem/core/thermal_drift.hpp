#pragma once
// The thermal drift law of the temperature-sensitive parameters, in one place:
//   r_s(T_w) = r_s,ref·(1 + α_Cu·(T_w − T_ref)),   ψm(T_m) = ψm,ref·(1 + α_PM·(T_m − T_ref)).
// The simulator applies it forwards; rpemd inverts it to derive temperatures from the estimates.

namespace rpem::core {

inline constexpr double kCopperCoeff_per_K = 0.00393;  ///< α_Cu, copper's resistance near 20 °C
inline constexpr double kNdFeBCoeff_per_K = -0.0012;   ///< α_PM, an NdFeB magnet's remanence

/// The law's coefficients (the reference values are the parameters' nominal ones, kept by the caller).
struct ThermalCoefficients {
  double reference_C = 20.0;
  double r_s_coeff_per_K = kCopperCoeff_per_K;
  double psi_m_coeff_per_K = kNdFeBCoeff_per_K;
};

/// value(T) / value_ref.
[[nodiscard]] constexpr double thermal_factor(double coeff_per_K, double temperature_C, double reference_C) noexcept {
  return 1.0 + coeff_per_K * (temperature_C - reference_C);
}

/// The temperature at which the law gives `value` (the inverse of thermal_factor).
[[nodiscard]] constexpr double thermal_temperature_C(double value, double value_ref, double coeff_per_K,
                                                     double reference_C) noexcept {
  return reference_C + (value / value_ref - 1.0) / coeff_per_K;
}

}  // namespace rpem::core
