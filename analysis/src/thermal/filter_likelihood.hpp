#pragma once
// What `rpem thermal fit` (thermal_fit.cpp) chooses by the filter's innovation likelihood over the training part
// (its first `training` steps), after or before the network: the noise intensities, the disturbances' correlation
// times (eq. 14.19, 14.21a) and the winding sensor's time constant (eq. 14.22, 14.25). Each writes its choice into
// the configuration and reports it in the fit's result. likelihood_ratio_threshold is declared in thermal_fit.hpp.

#include <cstddef>

#include "rpem/analysis/thermal/thermal_fit.hpp"

namespace rpem::analysis {

/// The filter's innovation log-likelihood over the training part.
[[nodiscard]] double training_log_likelihood(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t training);

/// The value of one of the filter's noise intensities (every node; `field` picks which) that maximises the
/// filter's innovation likelihood over the training part: golden-section search on its log10 in [lo, hi]. Set in `c`.
double maximum_likelihood(io::ThermalConfig& c, const ThermalRecord& r, std::size_t training,
                          core::ThermalVec core::ThermalFilterConfig::*field, double lo, double hi);

/// The disturbances' correlation times τ_d (eq. 14.19) jointly with q_d, per node (options.disturbance_time_constant_s
/// given: that one for every node), into out.config and out's τ_d fields.
void choose_disturbance_time_constants(ThermalFitResult& out, const ThermalRecord& record, std::size_t training,
                                       const ThermalFitOptions& options);

/// The winding sensor's τ_s without the network (eq. 14.25) from the training part's standstills in which r̂s
/// adapts beside the sensor; where it shows a lag, set in `c` with the winding node as the sensor's reading
/// (eq. 14.24). A parameter and a note in `out` either way (none without a standstill run).
void sensor_lag_at_standstill(io::ThermalConfig& c, const ThermalRecord& r, std::size_t training, ThermalFitResult& out);

/// The winding sensor's τ_s (eq. 14.22) of the largest innovation likelihood on the fitted network, set in `c`
/// where its profile-likelihood interval excludes no lag (else 0); a parameter and a note in `out`.
void fit_sensor_lag(io::ThermalConfig& c, const ThermalRecord& r, std::size_t training, ThermalFitResult& out);

}  // namespace rpem::analysis
