#pragma once
// The paper's analysis figures, computed from the closed-form steady-state analysis and the
// discretised predictor (rpem figures):
//   Fig_EigenTraj       eigenvalues vs speed (continuous) and spectral radius of the trapezoidal and
//                       explicit-Euler predictors at T_samp (discrete)
//   Fig_sensitivity     ε_d, ε_q over the speed-torque plane for −10 % ψ̂m and −10 % r̂s
//   fig_PEG_analytical  steady-state prediction gradients over the plane
//   fig_hesscompstatic  scalar Hessian r = tr{ΨΨᵀ} and |R| = det(ΨΨᵀ) over the plane

#include <string>
#include <vector>

#include "rpem/core/settings.hpp"

namespace rpem::analysis {

/// Writes the four figures into `dir`; returns the PNG paths.
std::vector<std::string> write_analysis_figures(const std::string& dir, const core::MachineSi& machine,
                                                double sample_period_s);

}  // namespace rpem::analysis
