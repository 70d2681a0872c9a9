#pragma once
// What the found effects do to the estimates (docs/diagnose.md, "The estimator with the extended
// model"). Transient logs: the RPEM estimator (core::DriveEstimator, exactly as `rpem estimate` and
// rpemd run it) over the log, once with the input configuration and once with the extended one.
// Steady-state logs, whose samples lie seconds apart, cannot drive the recursive estimator; there each
// row's steady-state equations give the ψm and R_s the data implies (with the extended model's input
// corrections and inductances), set against what each model assumes — the nominal model constant
// values, the extended one its drifts:
//   R_s = (u_d + ω·L_q·i_q)/i_d,   ψm = (u_q − R_s·i_q)/ω − L_d·i_d   (R_s there: the extended model's)

#include <optional>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/analysis/diagnose/monitor.hpp"
#include "rpem/analysis/work_pool.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {

/// Parameter trajectories, decimated, SI.
struct ParameterTrack {
  std::vector<double> t_s, psi_m_Wb, r_s_Ohm;
  void add(double t, double psi, double r) {
    t_s.push_back(t);
    psi_m_Wb.push_back(psi);
    r_s_Ohm.push_back(r);
  }
  [[nodiscard]] bool empty() const noexcept { return t_s.empty(); }
};

/// The true parameters of a simulated log (`rpem sim --truth`: columns t, psi_m, r_s).
[[nodiscard]] ParameterTrack load_truth(const std::string& path);

struct EstimateSummary {
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0;   ///< mean over the last quarter of the log
  std::optional<double> psi_m_error_pct;  ///< RMS error against truth over the second half
  std::optional<double> r_s_error_pct;
};

struct EstimatorComparison {
  std::string method;  ///< "rpem" or "steady_state"
  /// rpem: the estimates; steady_state: what each model assumes.
  ParameterTrack nominal, extended;
  /// rpem: the truth given (may be empty); steady_state: what the data implies. The summaries'
  /// errors are against it.
  ParameterTrack truth;
  EstimateSummary nominal_summary, extended_summary;
};

/// `extended` is the model with the found effects (drifts apply to the steady-state method only:
/// the recursive estimator tracks ψm and R_s itself); the steady-state method's "nominal" is the
/// context's baseline.
/// The two estimator runs go on `pool` at once; `monitor` (if any) is told the samples run and may stop them.
[[nodiscard]] EstimatorComparison compare_estimates(const LogData& log, const io::MachineConfig& nominal,
                                                    const io::MachineConfig& extended_config, const ExtendedModel& extended,
                                                    const EffectContext& context, const ParameterTrack& truth,
                                                    const WorkPool& pool = WorkPool::serial(), Monitor* monitor = nullptr);

/// RMS of the RPEM estimator's prediction error ε over the held-out blocks when it runs over the whole
/// log with `config` (docs/diagnose.md, "An extension must help the estimator") [A].
[[nodiscard]] double estimator_heldout_rms_A(const LogData& log, const io::MachineConfig& config,
                                             Monitor* monitor = nullptr);

}  // namespace rpem::analysis
