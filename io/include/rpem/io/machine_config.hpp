#pragma once
// Loads the machine + estimator configuration (schema: docs/configuration.md; example:
// config/paper-ipmsm.yaml). Unknown keys and out-of-range values are rejected with file:line.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rpem/core/settings.hpp"
#include "rpem/core/thermal.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::io {

/// A parameter's drift (model_extensions.rs_drift / psim_drift, found by `rpem diagnose`): against
/// temperature, the law of core/thermal.hpp (coeff_per_K, reference_C, r_s_ref_Ohm / psi_m_ref_Wb;
/// value_ref 0: the machine's), which `rpem diagnose` replays and which calibrates rpemd's temperature
/// derivation; or, where the log had no temperatures, its relative change over that log (informational).
struct ParameterDrift {
  std::optional<core::DriftLaw> law;
  std::optional<double> rel_change;  ///< change over the diagnosed log, relative to nominal
};

struct MachineConfig {
  core::MachineSi machine;
  core::EstimatorSettings estimator;
  ParameterDrift rs_drift;
  ParameterDrift psim_drift;
};

/// Reads the `machine`, `estimator` and optional `model_extensions` sections of `root`
/// (other sections are left for the caller, who calls root.finish()).
[[nodiscard]] MachineConfig parse_machine_config(YamlMap& root);

/// Where the configuration does not say where the drive's dq frame comes from (estimator.regimes.angle_source), for
/// rpemd's VESC source at start (most VESCs run sensorless, the default is a position sensor's frame): a note saying
/// so and which key changes it. Empty where the file says it. (The log tools say it from the data instead:
/// io::assumed_frame_note.)
[[nodiscard]] std::string unstated_frame_note(const MachineConfig& config);

/// Loads a whole file that holds only those sections.
[[nodiscard]] MachineConfig load_machine_config(const std::string& path);

/// The built-in configuration: config/paper-ipmsm.yaml compiled into the binary.
[[nodiscard]] const std::string& builtin_paper_config_text();
[[nodiscard]] MachineConfig builtin_paper_config();

/// Throws ConfigError when the configuration needs a column the log lacks (a dead time in seconds scales
/// with u_dc).
void check_log_supports(const MachineConfig& c, const std::string& config_name, bool log_has_u_dc,
                        const std::string& log_path);

/// The drive-log limits narrowed to a machine (core::machine_plausible): phase currents within 10·I_b, voltages (commands and DC
/// link) within 10·U_b, speed within 10·ω_b (peak phase base, docs/per-unit.md) — beyond any drive's
/// overload and field-weakening range, so a value there means the log's units or the configured name
/// plate are wrong. Never wider than the absolute limits.
[[nodiscard]] DriveLogLimits machine_limits(const core::MachineSi& machine);
/// machine_limits for the configuration's machine, with its drive's control period (the windows' shortest).
[[nodiscard]] DriveLogLimits log_limits(const MachineConfig& config);

/// The `model_extensions` section for a configuration's extensions and drifts (flow-style YAML that
/// parse_machine_config() reads back to the same values); empty when the model is nominal.
[[nodiscard]] std::string model_extensions_yaml(const MachineConfig& c);

/// `yaml_text` with values of the top-level `machine` section's own keys replaced (each pair: key, value),
/// each followed by `comment` and the value it replaced; the rest of the text is kept as it is. Throws
/// ConfigError if a key is not there.
[[nodiscard]] std::string replace_machine_values(const std::string& yaml_text,
                                                 const std::vector<std::pair<std::string, double>>& values,
                                                 const std::string& comment);

/// `yaml_text` with the values of `estimator.initial` (flow map or block) replaced where it gives those keys (each
/// pair: key, value), followed by `comment` and what they replaced; a text without them is returned as it is.
[[nodiscard]] std::string replace_estimator_initial(const std::string& yaml_text,
                                                    const std::vector<std::pair<std::string, double>>& values,
                                                    const std::string& comment);

/// `yaml_text` with its top-level `model_extensions` section (if any) replaced by `section`.
[[nodiscard]] std::string replace_model_extensions(const std::string& yaml_text, const std::string& section);

[[nodiscard]] const char* to_string(core::Algorithm a) noexcept;
[[nodiscard]] core::Algorithm parse_algorithm(const std::string& name);  ///< throws std::invalid_argument

}  // namespace rpem::io
