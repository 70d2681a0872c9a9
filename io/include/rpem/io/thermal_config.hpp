#pragma once
// The `thermal` section (docs/thermal.md, "thermal.yaml"): the machine's thermal network, the temperature
// laws the estimates are observed through, the coolant, a winding sensor and the filter's settings — what
// `rpem thermal fit` writes and `rpem estimate --thermal` and rpemd read. Strict: unknown keys and values
// out of range are ConfigErrors naming file:line:column and the key.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "rpem/core/thermal_fusion.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::io {

struct ThermalConfig {
  core::ThermalFusionConfig fusion;
  std::array<std::string, core::kMaxThermalNodes> node_names{};
  bool has_network = true;  ///< `nodes` given (a fit's start may give the laws only)
  /// Whether the temperature at which the copper law's r_s_ref holds was stated (the machine's `rs_drift` or
  /// the section's `copper`), or the machine's r_s_Ohm was assumed to hold at copper's 20 °C reference.
  bool copper_reference_stated = true;
  /// Whether the magnet law was stated (the machine's `psim_drift` or the section's `magnet_law`), or the machine's
  /// psi_m_Wb was assumed to hold at NdFeB's 20 °C reference.
  bool magnet_law_stated = true;
  /// Whether any node states its process noise or heat disturbance (either key, zero included); absent from every
  /// node, both are 0 and the filter takes the network as exact between observations (process_noise_note).
  bool process_noise_stated = true;
};

/// Whether a section must give the network (rpemd, `rpem estimate`) or may give the laws only (a fit's start).
enum class NetworkRequired : bool { kNo = false, kYes = true };

/// The `thermal` section itself (`section` is the mapping under the key). Defaults that depend on the
/// machine (loss base, the laws' reference values) come from `machine`.
[[nodiscard]] ThermalConfig parse_thermal_config(YamlMap& section, const MachineConfig& machine,
                                                 NetworkRequired network = NetworkRequired::kYes);

/// A file whose `thermal` section is read (other top-level sections are allowed and ignored, so a
/// whole rpemd configuration can be given).
[[nodiscard]] ThermalConfig load_thermal_config(const std::string& path, const MachineConfig& machine,
                                                NetworkRequired network = NetworkRequired::kYes);

/// Why the network has no steady state at the machine's rated point, or nothing if it settles there (eq. 14.27,
/// core::thermal_settles). The rated current is one the machine carries for ever, so its winding reaches a steady
/// temperature there: the reader refuses a section whose network does not (at `nodes`), and `rpem thermal fit`
/// does not write one.
[[nodiscard]] std::optional<std::string> runaway_at_rating(const ThermalConfig& c, const MachineConfig& machine);

/// What a reader should be told of the laws' assumptions (each a sentence, for a `note:`): the copper law's reference
/// temperature where it was not stated, the magnet law where it was not (`magnet`: whether to say the latter —
/// a fit anchors the magnet law at the log's soaked start instead).
[[nodiscard]] std::vector<std::string> assumed_law_notes(const ThermalConfig& c, bool magnet);

/// What a reader of a network should be told where no node states a process noise or a disturbance (a network
/// written by hand: `rpem thermal fit` writes both): the band then holds the start's and the observations'
/// uncertainty only, and is too narrow wherever the network is not exact. Nothing where one is stated.
[[nodiscard]] std::optional<std::string> process_noise_note(const ThermalConfig& c);

/// What a filter that starts soaked with nothing to test it says (core::start_temperatures_C; docs/thermal.md, "A log
/// that does not start soaked"): `untested_because`, why nothing tests the soak.
[[nodiscard]] std::string soaked_start_note(const std::string& untested_because);

/// The defaults a fit starts from (docs/thermal.md; no network: has_network false): the laws of the machine's
/// drifts or of copper and NdFeB (core/thermal.hpp) about the machine's values at 20 °C, the loss base
/// of the machine (core::loss_base_of).
[[nodiscard]] ThermalConfig default_thermal_config(const MachineConfig& machine);

/// The section as YAML text ("thermal:\n  …"), which parse_thermal_config() reads back to the same values.
[[nodiscard]] std::string thermal_config_yaml(const ThermalConfig& c);

/// The index of a node name, −1 if none.
[[nodiscard]] int node_index(const ThermalConfig& c, const std::string& name);

}  // namespace rpem::io
