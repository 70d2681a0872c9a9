#pragma once
// `source: {type: sim, sim: {scenario: builtin:rpemd-demo, loop: true}}` — the drive simulator
// (rpem::sim) paced in real time: a scenario file (docs/scenarios.md) or the built-in demonstration,
// restarted at its end when `loop`. Its report carries the simulated machine's true ψm and r_s.

#include <memory>
#include <string>

#include "rpem/daemon/read_at_parse.hpp"
#include "rpem/daemon/source.hpp"
#include "rpem/io/yaml_map.hpp"
#include "rpem/sim/scenario.hpp"

namespace rpem::daemon {

struct SimSource {
  static constexpr const char* kType = "sim";
  struct Options {
    std::string scenario = "builtin:rpemd-demo";  ///< a file (relative to the configuration) or builtin:rpemd-demo
    bool loop = true;
    ReadAtParse<sim::Scenario> scenario_read;  ///< the scenario as checked (none before a parse: the built-in demo)
    bool operator==(const Options&) const = default;
  };
  [[nodiscard]] static Options parse(io::YamlMap& section, const std::string& base_dir);
  [[nodiscard]] static SampleKind sample_kind(const Options&) noexcept { return SampleKind::kPhase; }
  /// Runs the scenario `parse` read; options made without a parse load theirs (io::ConfigError if it is bad).
  [[nodiscard]] static std::unique_ptr<SampleSource> make(const Options& options);
};

/// The built-in scenario's text (scenarios/rpemd-demo.yaml, compiled in).
[[nodiscard]] const std::string& builtin_demo_scenario_text();

}  // namespace rpem::daemon
