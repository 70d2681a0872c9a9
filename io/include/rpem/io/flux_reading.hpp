#pragma once
// What a log's back EMF says of ψm, against the configuration (docs/drive-log.md, "A configuration of another
// machine"): the tools' first check that the configuration given (or the built-in paper machine's, where none is)
// describes the machine that wrote the log.

#include <optional>
#include <string>
#include <vector>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::io {

/// ψm as the log's windows read it: the median over the windows that modulate and turn faster than ψm's gain
/// schedule (estimator.scheduler.psi_m_min_speed_rpm) of (u_q − R_s·i_q − ω·L_d·i_d)/ω, with the median of what the
/// configuration's uncertainty allows each (its inductance tolerance on L_d·|i_d|, the R_s bounds on R_s·|i_q|/|ω|).
struct FluxReading {
  std::size_t windows = 0;  ///< 0: no window modulates above that speed
  double psi_m_Wb = 0.0;
  double allowance_Wb = 0.0;
};
[[nodiscard]] FluxReading flux_reading(const std::vector<core::AveragedSample>& samples, const MachineConfig& config);

/// A note where the reading, widened by its allowance, lies wholly outside estimator.bounds.psi_m_Wb: the
/// estimator could not reach the log's ψm, and the configuration is most likely another machine's.
[[nodiscard]] std::optional<std::string> flux_mismatch_note(const FluxReading& reading, const MachineConfig& config);

}  // namespace rpem::io
