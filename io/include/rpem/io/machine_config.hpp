#pragma once
// Loads the machine + estimator configuration (schema: docs/configuration.md; example:
// config/paper-ipmsm.yaml). Unknown keys and out-of-range values are rejected with file:line.

#include <string>

#include "rpem/core/settings.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::io {

struct MachineConfig {
  core::MachineSi machine;
  core::EstimatorSettings estimator;
};

/// Reads the `machine`, `estimator` and optional `model_extensions` sections of `root`
/// (other sections are left for the caller, who calls root.finish()).
[[nodiscard]] MachineConfig parse_machine_config(YamlMap& root);

/// Loads a whole file that holds only those sections.
[[nodiscard]] MachineConfig load_machine_config(const std::string& path);

/// The built-in configuration: config/paper-ipmsm.yaml compiled into the binary.
[[nodiscard]] const std::string& builtin_paper_config_text();
[[nodiscard]] MachineConfig builtin_paper_config();

[[nodiscard]] const char* to_string(core::Algorithm a) noexcept;
[[nodiscard]] core::Algorithm parse_algorithm(const std::string& name);  ///< throws std::invalid_argument

}  // namespace rpem::io
