#pragma once
// The estimator's configuration as users write it: SI quantities with their units in the names,
// dimensionless gain sequences and floors in pu (as in tab_psimgains). make_estimator_config()
// converts it, through PerUnitBase, into the per-unit EstimatorConfig the real-time code runs on.

#include <array>

#include "rpem/core/averaged_settings.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/per_unit.hpp"

namespace rpem::core {

/// Machine data in SI (tab_machineData).
struct MachineSi {
  RatedData rated;
  double r_s_Ohm = 0.0;
  double l_d_H = 0.0;
  double l_q_H = 0.0;
  double psi_m_Wb = 0.0;
};

struct EstimatorSettings {
  Algorithm algorithm = Algorithm::kSga;
  Discretization discretization = Discretization::kTrapezoidal;
  GradientForm gradient_psi_m = GradientForm::kSteadyState;
  GradientForm gradient_r_s = GradientForm::kSteadyState;
  std::array<GainSequences, 3> gains{};  ///< indexed by Algorithm
  GainFloors floors;
  double psi_m_min_speed_rpm = 0.0;  ///< n_lim,1, mechanical
  double r_s_max_speed_rpm = 0.0;    ///< n_lim,2, mechanical
  double psi_m_min_Wb = 0.0, psi_m_max_Wb = 0.0;
  double r_s_min_Ohm = 0.0, r_s_max_Ohm = 0.0;
  double initial_psi_m_Wb = 0.0;
  double initial_r_s_Ohm = 0.0;
  Vec2 initial_sga_hessian_pu = Vec2::Zero();
  Mat2 initial_gna_hessian_pu = Mat2::Zero();
  double nominal_sample_period_s = 125e-6;
  double max_sample_interval_s = 1e-3;
  double max_gap_carry_s = 20e-3;
  bool adapt_psi_m = true;
  bool adapt_r_s = true;
  ModelExtensions extensions;  ///< model_extensions (docs/model-extensions.md)
  AveragedSettings averaged;   ///< the averaged-sample estimator (averaged_estimator.hpp)
};

[[nodiscard]] MachinePu to_pu(const PerUnitBase& base, const MachineSi& m) noexcept;
[[nodiscard]] EstimatorConfig make_estimator_config(const PerUnitBase& base, const MachineSi& m,
                                                    const EstimatorSettings& s) noexcept;

}  // namespace rpem::core
