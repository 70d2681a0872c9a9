#pragma once
// Logs without d/q values (docs/drive-log.md, "Logs without d/q values"; docs/derivations.md §13, "Voltages
// from the duty cycle"): loggers that keep what VESC's COMM_GET_VALUES gives besides the d/q means — the duty
// cycle, the input voltage, erpm and the motor current — and either leave the d/q columns out (VESC Tool
// 1.17–1.19) or write 0 in every row of them (SD and Arduino loggers built on VescUart that print VESC Tool's
// header). The rotor-frame values are rebuilt from them, in steady state and with i_d = 0:
//   |u| = |duty|·u_dc/√3 (times sinc(ω·T_c/2) where the duty is a command held for T_c),
//   u_d = R_s·i_d − ω·L_q·i_q,  u_q = sign(duty)·√(|u|² − u_d²),  i_q = sign(duty)·i_motor.
// The voltages so rebuilt are applied rotor-frame means: the estimator takes them with
// core::for_applied_voltages.

#include <cstdint>
#include <string>
#include <vector>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::io {

/// What complete_rotor_frame rebuilt.
struct RotorFrameRebuild {
  bool voltages = false;  ///< u_d, u_q from the duty cycle and u_dc
  bool currents = false;  ///< i_d = 0, i_q from the motor current
  /// Samples whose magnitude |u| is below the model's |u_d| (not in steady state, or L_q off): u_d is held to ±|u|
  /// and u_q is 0 there.
  std::uint64_t short_magnitude = 0;
  /// Whether anything was rebuilt.
  [[nodiscard]] bool any() const noexcept { return voltages || currents; }
  /// For the tools' summary: what was rebuilt and from what (empty: nothing).
  [[nodiscard]] std::string describe() const;
};

/// Rebuilds the rotor-frame voltages where the log has a duty cycle and u_dc but no u_d, u_q columns or 0 in every
/// row of them (while a duty is not 0 somewhere), and the currents where it has the motor current but no i_d, i_q or
/// 0 in every row of them (while the motor current is not), with the configured machine's R_s and L_q; a duty that
/// is a command held for `command_hold_s` (T_c; 0: the period's mean) is shortened by sinc(ω·T_c/2). Otherwise
/// checks that the voltages were recorded (check_voltages_recorded). Throws DriveLogError where a sample to rebuild
/// has no u_dc.
RotorFrameRebuild complete_rotor_frame(std::vector<core::AveragedSample>& samples, const AveragedLogRead& read,
                                       const core::MachineSi& machine, double command_hold_s, const std::string& log_path);

/// T_c where the configuration says the drive reports the command it holds for T_c; 0 otherwise.
[[nodiscard]] double command_hold_s(const core::EstimatorSettings& s) noexcept;

/// The settings `config`'s estimator runs the samples with: for_applied_voltages where their voltages were rebuilt.
[[nodiscard]] core::EstimatorSettings estimator_settings(const MachineConfig& config, const RotorFrameRebuild& rebuilt);

}  // namespace rpem::io
