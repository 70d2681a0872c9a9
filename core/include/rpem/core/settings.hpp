#pragma once
// The estimator's configuration as users write it: SI quantities with their units in the names,
// dimensionless gain sequences and floors in pu (as in tab_psimgains). make_estimator_config()
// converts it, through PerUnitBase, into the per-unit EstimatorConfig the real-time code runs on.

#include <array>

#include "rpem/core/averaged_settings.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/core/regime.hpp"

namespace rpem::core {

/// Machine data in SI (tab_machineData).
struct MachineSi {
  RatedData rated;
  double r_s_Ohm = 0.0;
  double l_d_H = 0.0;
  double l_q_H = 0.0;
  double psi_m_Wb = 0.0;
};

/// The options shared with EstimatorConfig (estimator.hpp, where their defaults are), plus what the
/// user gives in SI: scheduler speeds, D_M, initial values, model extensions.
struct EstimatorSettings : EstimatorOptions {
  double psi_m_min_speed_rpm = 0.0;  ///< n_lim,1, mechanical
  double r_s_max_speed_rpm = 0.0;    ///< n_lim,2, mechanical
  double psi_m_min_Wb = 0.0, psi_m_max_Wb = 0.0;
  double r_s_min_Ohm = 0.0, r_s_max_Ohm = 0.0;
  double initial_psi_m_Wb = 0.0;
  double initial_r_s_Ohm = 0.0;
  ModelExtensions extensions;  ///< model_extensions (docs/model-extensions.md)
  AveragedSettings averaged;   ///< the averaged-sample estimator (averaged_estimator.hpp)
  RegimeSettings regimes;      ///< the regime classification (regime.hpp)
};

[[nodiscard]] MachinePu to_pu(const PerUnitBase& base, const MachineSi& m) noexcept;
[[nodiscard]] EstimatorConfig make_estimator_config(const PerUnitBase& base, const MachineSi& m,
                                                    const EstimatorSettings& s) noexcept;
/// The gain rates [1/s] for each algorithm where samples come at their own times (averaged windows, sparse
/// rows): `averaged.rates_per_s` where given, else γ_0/sample_period_s of `gains`.
[[nodiscard]] std::array<GainSequences, 3> averaged_rates_per_s(const EstimatorSettings& s) noexcept;
/// The settings for averaged samples whose voltages are already the applied rotor-frame means (a reported command
/// turned at reading, or voltages rebuilt in the rotor frame from their magnitude): neither the reported command's
/// turn (averaged.voltage_is_command) nor the delay's is made again.
[[nodiscard]] EstimatorSettings for_applied_voltages(EstimatorSettings s) noexcept;
/// The classifier's configuration: the nominal machine, D_M, the tolerances and resolutions, per unit.
[[nodiscard]] RegimeConfig make_regime_config(const PerUnitBase& base, const MachineSi& m,
                                              const EstimatorSettings& s) noexcept;

}  // namespace rpem::core
