#pragma once
// What the found effects do to the estimates (docs/diagnose.md, "The estimator with the extended
// model"). Transient logs: the RPEM estimator (core::DriveEstimator, exactly as `rpem estimate` and
// rpemd run it) over the log, once with the input configuration and once with the extended one.
// Steady-state logs, whose samples lie seconds apart, cannot drive the recursive estimator; there each
// row's steady-state equations give the ψm and R_s the data implies (with the extended model's input
// corrections and inductances), set against what each model assumes — the nominal model constant
// values, the extended one its drifts:
//   R_s = (u_d + ω·L_q·i_q)/i_d,   ψm = (u_q − R_s·i_q)/ω − L_d·i_d   (R_s there: the extended model's)
// A row implies a value only where the data's noise determines it: the value stands out of its standard
// deviation (the noise of u, i and ω propagated to first order) by the classification's z (docs/diagnose.md,
// "The estimator with the extended model"); elsewhere — ω near zero for ψm, i_d near zero for R_s, as on a
// drive that holds i_d at 0 — the row implies nothing of that parameter (NaN). Set against them, a model's error
// is the median of the relative error's magnitude: a few rows the steady-state model cannot represent imply
// anything at all. Where a truth is given, every error is against it (RMS), on either kind of log.

#include <optional>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/monitor.hpp"
#include "rpem/analysis/work_pool.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {

/// Parameter trajectories, decimated, SI.
struct ParameterTrack {
  std::vector<double> t_s, psi_m_Wb, r_s_Ohm;  ///< NaN: not determined at that row (implied values)
  void add(double t, double psi, double r) {
    t_s.push_back(t);
    psi_m_Wb.push_back(psi);
    r_s_Ohm.push_back(r);
  }
  [[nodiscard]] bool empty() const noexcept { return t_s.empty(); }
};

/// The estimates are judged against a truth over the log's second half (the first is the estimator's start).
inline constexpr double kJudgedFromFraction = 0.5;

/// A truth CSV (t, psi_m, r_s: `rpem sim --truth`) that covers [judged_from_s, judged_to_s]: times increasing, values
/// finite and positive; one row is a constant truth. Else io::DriveLogError naming the file, the row and why.
[[nodiscard]] ParameterTrack load_truth(const std::string& path, double judged_from_s, double judged_to_s);

struct EstimateSummary {
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0;  ///< mean over the last quarter of the log
  /// The error over the second half, at the rows where the reference is determined (none: empty): the RMS against
  /// a true track, else the median of its magnitude against what the rows imply (steady_state).
  std::optional<double> psi_m_error_pct;
  std::optional<double> r_s_error_pct;
};

struct EstimatorComparison {
  std::string method;  ///< "rpem" or "steady_state"
  /// rpem: the estimates; steady_state: what each model assumes.
  ParameterTrack nominal, extended;
  /// The truth given (`--truth`; may be empty).
  ParameterTrack truth;
  /// steady_state: what each row of the tracks implies (NaN where not determined); rpem: empty.
  ParameterTrack implied;
  EstimateSummary nominal_summary, extended_summary;

  /// What the summaries' errors are against: "truth" where one was given, else "implied" (steady_state), else "".
  [[nodiscard]] const char* judged_against() const noexcept {
    return !truth.empty() ? "truth" : !implied.empty() ? "implied" : "";
  }
};

/// `extended` is the model with the found effects (drifts apply to the steady-state method only:
/// the recursive estimator tracks ψm and R_s itself); the steady-state method's "nominal" is the
/// context's baseline.
/// `noise_pu` is the data's noise (LogRegimes::noise_pu), which decides where a steady-state row determines a value.
/// The two estimator runs go on `pool` at once; `monitor` (if any) is told the samples run and may stop them.
[[nodiscard]] EstimatorComparison compare_estimates(const LogData& log, const io::MachineConfig& nominal,
                                                    const io::MachineConfig& extended_config, const ExtendedModel& extended,
                                                    const EffectContext& context, const ParameterTrack& truth,
                                                    const core::RegimeNoise& noise_pu,
                                                    const WorkPool& pool = WorkPool::serial(), Monitor* monitor = nullptr);

/// RMS of the RPEM estimator's prediction error ε over the held-out blocks when it runs over the whole
/// log with `config` (docs/diagnose.md, "An extension must help the estimator") [A].
[[nodiscard]] double estimator_heldout_rms_A(const LogData& log, const io::MachineConfig& config,
                                             Monitor* monitor = nullptr);

}  // namespace rpem::analysis
