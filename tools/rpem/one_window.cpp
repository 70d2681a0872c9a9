#include "one_window.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/assert.hpp"
#include "rpem/core/averaged_estimator.hpp"

namespace rpem::tools {

double estimate_at_end(const std::vector<core::AveragedSample>& samples, const core::MachineSi& machine,
                       const core::EstimatorSettings& settings, std::size_t parameter, std::optional<std::size_t> frozen) {
  RPEM_ASSERT(parameter < 2, "psi_m or r_s");
  core::AveragedDriveEstimator run(machine, settings);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    run.set_frozen(frozen == i);
    (void)run.step(samples[i]);
  }
  run.set_frozen(false);
  run.end_chain();
  return parameter == 0 ? run.psi_m_Wb() : run.r_s_Ohm();
}

std::optional<DecidingWindow> window_that_decides(const std::vector<core::AveragedSample>& samples,
                                                  const io::MachineConfig& cfg, std::size_t parameter,
                                                  const std::vector<AdaptationStep>& steps, double estimate,
                                                  double tolerance) {
  const double asked = tolerance * std::abs(estimate);
  std::vector<AdaptationStep> candidates;
  for (const AdaptationStep& s : steps)
    if (std::abs(s.change) > asked && s.index < samples.size()) candidates.push_back(s);
  std::sort(candidates.begin(), candidates.end(),
            [](const AdaptationStep& a, const AdaptationStep& b) { return std::abs(a.change) > std::abs(b.change); });
  if (candidates.size() > kMaxWindowsRunAgain) candidates.resize(kMaxWindowsRunAgain);
  for (const AdaptationStep& c : candidates) {
    const double without = estimate_at_end(samples, cfg.machine, cfg.estimator, parameter, c.index);
    if (std::abs(without - estimate) > asked) return DecidingWindow{c.index, c.change, without};
  }
  return std::nullopt;
}

}  // namespace rpem::tools
