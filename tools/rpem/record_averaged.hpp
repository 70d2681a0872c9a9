#pragma once
// rpem record --averaged-out AVG.csv: averaged rotor-frame drive logs (io/averaged_log.hpp,
// docs/drive-log.md "Averaged log") from any source rpemd reads:
//   --signal-map MAP.yaml   a drive's own frames (CiA 402 PDOs, a LispBM script, custom firmware)
//   --vesc-id N             a VESC polled with COMM_GET_VALUES_SELECTIVE (docs/can-vesc.md)
//   (neither)               rpem's native telemetry, averaged over windows of 1/--window-rate
// Shared stop conditions with the native recorder: --duration, --samples, --idle-timeout.

#include <cstdint>
#include <string>

namespace rpem::tools {

struct RecordOptions {
  std::string interface;
  std::string out;           ///< native drive log (phase samples)
  std::string averaged_out;  ///< averaged log
  double duration_s = 0.0;
  std::uint64_t samples = 0;
  double idle_timeout_s = 0.0;
  bool latency = false;
  std::string signal_map;  ///< --signal-map
  int vesc_id = -1;        ///< --vesc-id; −1: not a VESC
  int host_id = 254;       ///< the poller's node id
  double poll_rate_Hz = 200.0;
  double window_rate_Hz = 200.0;  ///< native telemetry's averaging windows
};

/// Records averaged samples until a stop condition, SIGINT or SIGTERM.
int run_record_averaged(const RecordOptions& options);

}  // namespace rpem::tools
