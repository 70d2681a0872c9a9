#include <memory>

#include "rpem/analysis/reproduction.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/sim/drive_simulator.hpp"

namespace rpem::analysis {

CaseResult run_case(const ReproductionCase& c, double decimation_s) {
  CaseResult result;
  result.case_id = c.id;
  sim::DriveSimulator simulator(c.scenario);
  const core::MachineSi& machine = c.scenario.machine.machine;

  std::array<std::unique_ptr<core::DriveEstimator>, 3> estimators;
  auto make_estimators = [&] {
    for (std::size_t a = 0; a < kAlgorithms.size(); ++a) {
      core::EstimatorSettings s = c.estimator;
      s.algorithm = kAlgorithms[a];
      estimators[a] = std::make_unique<core::DriveEstimator>(machine, s);
      result.runs[a].algorithm = kAlgorithms[a];
    }
  };
  if (c.kind != CaseKind::kStartWithError) make_estimators();
  if (c.kind == CaseKind::kDisturbance || c.kind == CaseKind::kParameterStep) {
    // Start converged: seed the estimates with the machine's initial parameters.
    const double psi = c.scenario.signal(sim::Quantity::kPsiM).initial();
    const double rs = c.scenario.signal(sim::Quantity::kRs).initial();
    for (auto& e : estimators) e->set_estimates(psi, rs);
  }

  const std::int64_t decimation = std::max<std::int64_t>(1, std::llround(decimation_s / c.scenario.sample_period_s));
  std::array<std::vector<TrajectoryPoint>, 3> full;
  io::DriveLogRow row;
  sim::TruthRow truth;
  std::int64_t k = 0;
  while (simulator.next(row, truth)) {
    const double t = core::to_seconds(row.sample.t_ns);
    if (!estimators[0] && t >= c.step_time_s) make_estimators();
    if (estimators[0]) {
      const double true_value = c.parameter == core::Param::kPsiM ? truth.parameters.psi_m_Wb : truth.parameters.r_s_Ohm;
      for (std::size_t a = 0; a < 3; ++a) {
        const core::Estimate e = estimators[a]->step(row.sample);
        const double est = c.parameter == core::Param::kPsiM ? e.psi_m_Wb : e.r_s_Ohm;
        full[a].push_back({t, est, true_value});
        if (k % decimation == 0) result.runs[a].trajectory.push_back({t, est, true_value});
      }
    }
    ++k;
  }
  ConvergenceOptions options;
  options.step_time_s = c.step_time_s;
  options.final_window_s = 1.0;
  for (std::size_t a = 0; a < 3; ++a) result.runs[a].metrics = convergence_metrics(full[a], options);
  return result;
}

}  // namespace rpem::analysis
