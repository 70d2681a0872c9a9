#pragma once
// `rpem thermal fit` (docs/thermal.md): the thermal network's capacitances, conductances and loss
// coefficients fitted, with the magnet law's reference value anchored at the soaked start, to what a log shows of the temperatures — a
// winding sensor, the magnet temperature from ψ̂m, the winding's from r̂s (thermal_record.hpp) — by
// weighted nonlinear least squares of the open-loop network (Ceres), every positive quantity as its
// logarithm (positive by construction). The part of the log after `fit_until_s` is held out and judged.
// Intervals and identifiability as `rpem diagnose` reports them (effect_fit.hpp): cluster-robust 95 %
// intervals over blocks of the training part, what the excitation alone allows, identified when the
// robust half-width is at most kIdentifiedHalfWidth. The process noise of the filter is then the
// maximum-likelihood one of the filter's innovations over the training part.

#include <limits>
#include <string>
#include <vector>

#include "rpem/analysis/thermal/coolant_drift.hpp"
#include "rpem/analysis/thermal/thermal_record.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::analysis {

/// The fewest steps of the filter a fit takes, in the log and in its training part.
inline constexpr std::size_t kMinFitSteps = 10;

struct ThermalFitOptions {
  /// Steps ending at or before this time train; the rest is held out. NaN: the first 75 % of the log's time.
  double fit_until_s = std::numeric_limits<double>::quiet_NaN();
  int blocks = 8;  ///< clusters of the training part for the robust intervals
  /// The magnet law's ψ_ref from the first magnet observations at the soaked start (else as configured).
  bool anchor_magnet_reference = true;
  int max_iterations = 200;
  /// τ_d of eq. 14.19 for every node if given (≥ 1e9 s: the walk); NaN: each node's chosen with q_d by the likelihood.
  double disturbance_time_constant_s = std::numeric_limits<double>::quiet_NaN();
};

/// The steps of `r` that end at or before `fit_until_s`: the training part a fit to that time has.
[[nodiscard]] std::size_t steps_until(const ThermalRecord& r, double fit_until_s);

struct FittedParameter {
  std::string name;  ///< e.g. "C winding", "G winding–magnet", "iron_eddy at magnet", "psi_m_ref"
  std::string unit;  ///< SI; "1" for a ratio
  /// The unit as it follows a value in text: " W/K", nothing for a ratio.
  [[nodiscard]] std::string unit_after_value() const { return unit == "1" ? std::string() : " " + unit; }
  double value = 0.0;
  double half_width_rel = 0.0;             ///< 95 %, cluster-robust, relative (∞: not excited)
  double excitation_half_width_rel = 0.0;  ///< 95 %, what the excitation alone allows
  bool identified = false;
};

/// How well the network follows one observed signal [K]: on the training and on the held-out part.
struct SignalFit {
  std::string name;
  std::size_t fit_points = 0, heldout_points = 0;
  double fit_rms_K = 0.0, heldout_rms_K = 0.0, heldout_worst_K = 0.0;
  /// What the training part observes: the temperatures between its 5th and 95th percentile [°C] (NaN where it has
  /// none of this signal), and the σ of one observation as the fit weighs it (the median over the training part) [K].
  /// A network is identified only by temperatures the losses move by many of these σ.
  double training_low_C = 0.0, training_high_C = 0.0, training_sigma_K = 0.0;
};

struct ThermalFitResult {
  io::ThermalConfig config;  ///< the fitted section
  double fit_until_s = 0.0;
  std::size_t training_steps = 0;
  std::vector<FittedParameter> parameters;
  std::vector<SignalFit> signals;
  /// Parameters that move together where the log cannot tell them apart (the weakest directions of the
  /// information matrix), as text.
  std::vector<std::string> not_identifiable;
  std::vector<std::string> notes;
  double process_noise_K2_per_s = 0.0;
  double disturbance_W2_per_s = 0.0;
  /// τ_d of eq. 14.19 per node (+∞: the random walk), with q_d the most likely over the training part.
  core::ThermalVec disturbance_time_constant_s = core::ThermalVec::Constant(std::numeric_limits<double>::infinity());
  /// Each τ_d tried: the node (−1: all nodes), τ_d (+∞ first: the walk) and the training part's log-likelihood,
  /// q_d refitted.
  struct TimeConstantTrial {
    int node = -1;
    double time_constant_s = 0.0;
    double log_likelihood = 0.0;
  };
  std::vector<TimeConstantTrial> disturbance_time_constant_log_likelihood;
  /// The gain in log-likelihood a chosen τ_d had to show over the walk (eq. 14.21a; 0 where τ_d was given).
  double disturbance_time_constant_threshold = 0.0;
  /// q_c of an unread coolant (eq. 14.29b) from the training part's coolant readings; also in config (0: none read).
  CoolantDrift coolant_drift;
  double training_cost = 0.0;                 ///< Σ of the squared weighted residuals
  std::vector<core::ThermalVec> open_loop_C;  ///< the model alone over the whole log, per step
};

/// Fits `start` (its nodes, conductances and losses give the topology; their values the start) to the record.
[[nodiscard]] ThermalFitResult fit_thermal(const ThermalRecord& record, const io::ThermalConfig& start,
                                           const ThermalFitOptions& options);

/// The log-likelihood gain over the walk a node's correlation time τ_d chosen from `trials` grid points must show
/// (eq. 14.21a): ½·χ²₁(1 − 0.05/trials), the likelihood-ratio test at 5 % with Bonferroni's correction.
[[nodiscard]] double likelihood_ratio_threshold(std::size_t trials);

}  // namespace rpem::analysis
