#pragma once
// `source: {type: can, can: {interface: can0}}` — the drive's telemetry from a SocketCAN interface
// (docs/can-protocol.md), decoded by rpem::can; the socket reopens by itself when the interface goes
// down and up. Its counters are the decoder's and the socket's (can_* in diagnostics_t).

#include <memory>
#include <string>

#include "rpem/daemon/source.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::daemon {

struct CanSource {
  static constexpr const char* kType = "can";
  struct Options {
    std::string interface = "can0";
    bool operator==(const Options&) const = default;
  };
  [[nodiscard]] static Options parse(io::YamlMap& section, const std::string& base_dir);
  [[nodiscard]] static SampleKind sample_kind(const Options&) noexcept { return SampleKind::kPhase; }
  [[nodiscard]] static std::unique_ptr<SampleSource> make(const Options& options);
};

}  // namespace rpem::daemon
