#pragma once
// Reads a signal map (docs/sources.md, "Signal maps") from YAML into can::SignalMap, refusing — with
// ConfigError naming file:line and key — unknown fields, a unit other than the field's, signals outside
// their frame, and a map that does not give what the estimator needs.

#include <string>

#include "rpem/can/signal_map.hpp"

namespace rpem::io {

[[nodiscard]] can::SignalMap load_signal_map(const std::string& path);
/// The same from text; `name` stands in for the file name in messages.
[[nodiscard]] can::SignalMap parse_signal_map(const std::string& text, const std::string& name);

}  // namespace rpem::io
