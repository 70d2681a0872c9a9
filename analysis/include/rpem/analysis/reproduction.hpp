#pragma once
// The paper's validation cases (Sections V and VI) on the simulated drive, each run with SGA, GNA and
// PhyInt on the same simulated samples. docs/reproduction.md sets the results beside the paper's.
//
// Section V (ERTS): the physical ψm or R_s steps by −8 % while the estimators run, converged.
// Section VI (bench): the estimators start with the offline values while the machine's parameter is
// 8 % lower (ψm, R_s cases), or run converged through a speed or load transient (disturbance cases).

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "rpem/analysis/convergence.hpp"
#include "rpem/analysis/standstill_rs.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/sim/scenario.hpp"

namespace rpem::analysis {

inline constexpr std::array<core::Algorithm, 3> kAlgorithms = {core::Algorithm::kSga, core::Algorithm::kGna,
                                                               core::Algorithm::kPhyInt};

enum class CaseKind {
  kParameterStep,   ///< Section V: the machine's parameter steps at step_time_s
  kStartWithError,  ///< Section VI: the estimators start at step_time_s from the offline value
  kDisturbance,     ///< Section VI: a speed or load transient at step_time_s; the parameter is constant
};

/// What a case stands for in the comparison with the paper.
enum class CaseRole {
  kPaper,       ///< a panel of the paper, run with the settings the paper states (tab_psimgains)
  kHypothesis,  ///< a panel run with settings the paper does not state, to test an explanation of its numbers
  kStudy,       ///< a variant that shows why a result is what it is (a gain, an initial Hessian)
};

[[nodiscard]] const char* to_string(CaseRole r) noexcept;

/// What the paper reports for a case (tab_comparison), per algorithm (SGA, GNA, PhyInt).
struct PaperFigures {
  std::array<std::optional<double>, 3> convergence_time_s;
  std::array<std::optional<double>, 3> steady_state_error_pct;
  std::string qualitative;  ///< the paper's words where it gives no number
};

struct ReproductionCase {
  std::string id;      ///< e.g. "V_psim_a"
  std::string figure;  ///< the paper's \label and panel, e.g. "fig_psim_adapt (a)"
  std::string description;
  CaseRole role = CaseRole::kPaper;
  std::string study_figure;  ///< hypothesis and study cases: the PNG they are drawn in (without .png)
  core::Param parameter = core::Param::kPsiM;
  CaseKind kind = CaseKind::kParameterStep;
  double n_pu = 0.0;    ///< operating speed (before a disturbance)
  double tau_pu = 0.0;  ///< electromagnetic torque (Section V) or load torque (Section VI)
  double step_time_s = 0.0;
  sim::Scenario scenario;
  core::EstimatorSettings estimator;  ///< the algorithm is set per run
  PaperFigures paper;
};

struct AlgorithmRun {
  core::Algorithm algorithm = core::Algorithm::kSga;
  std::vector<TrajectoryPoint> trajectory;  ///< decimated, SI (Wb or Ω)
  ConvergenceMetrics metrics;
};

struct CaseResult {
  std::string case_id;
  std::array<AlgorithmRun, 3> runs;
};

/// All cases of Sections V and VI.
[[nodiscard]] std::vector<ReproductionCase> paper_cases();

/// Simulates one case and runs the three algorithms on its samples. Trajectories are decimated to
/// `decimation_s`; metrics are computed at the full sample rate.
[[nodiscard]] CaseResult run_case(const ReproductionCase& c, double decimation_s = 0.01);

[[nodiscard]] const char* parameter_name(core::Param p) noexcept;

/// Where the estimate starts relative to the machine's parameter (r̂/r − 1 or ψ̂/ψ − 1) in a
/// start-with-error case: the offline value against the scenario's initial one.
[[nodiscard]] double initial_error(const ReproductionCase& c);

/// An R_s case at standstill as the scalar recursion of standstill_rs.hpp sees it, for SGA or GNA: the
/// case's R_s gain sequences, and its initial Hessian relative to the settled (i/r_s)² at the load's
/// MTPA current.
[[nodiscard]] StandstillRs standstill_rs_model(const ReproductionCase& c, core::Algorithm a);

}  // namespace rpem::analysis
