#pragma once
// The network `rpem thermal fit` starts from where the configuration gives none (docs/thermal.md, "The network").

#include "rpem/analysis/thermal/thermal_record.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::analysis {

/// The default topologies (docs/thermal.md, "The network"): 2 nodes (winding, magnet) or 3 (winding,
/// stator_iron, magnet), with starting values scaled to the record's copper loss and temperature rise.
[[nodiscard]] io::ThermalConfig default_topology(const io::ThermalConfig& laws, const ThermalRecord& record, int nodes);

}  // namespace rpem::analysis
