#pragma once
// rpemd's configuration (docs/rpemd.md, examples in config/): an optional `daemon` section beside the
// machine configuration sections (`machine`, `estimator`, `model_extensions`) — so a machine file such
// as `rpem diagnose`'s extended.yaml is also a complete rpemd configuration — or
// `daemon.machine_config` pointing at one. Strict: unknown keys and out-of-range values are errors
// (ConfigError; rpemd exits 78).

#include <cstdint>
#include <string>

#include "rpem/core/thermal.hpp"
#include "rpem/daemon/realtime.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::daemon {

enum class SourceType { kSim, kCan };
enum class RealtimeMode { kRequired, kPreferred, kOff };

/// Winding and magnet temperatures from r̂s and ψ̂m: the inverse of the drift laws (core/thermal.hpp);
/// value_ref defaults to the machine's offline r_s and ψm.
using TemperatureModel = core::ThermalModel;

struct ValidityConfig {
  double r_s_after_s = 2.0;          ///< r_s valid after this much standstill adaptation (then held)
  double psi_m_after_s = 1.0;        ///< ψm valid after this much adaptation, while above the speed limit
  double convergence_window_s = 2.0;
  double convergence_band = 0.002;   ///< relative spread over the window
};

struct DaemonConfig {
  std::string source_file;  ///< where it was loaded from ("<built-in>")
  io::MachineConfig machine;

  SourceType source = SourceType::kSim;
  std::string can_interface = "can0";
  std::string sim_scenario = "builtin:rpemd-demo";
  bool sim_loop = true;

  double loop_period_s = 125e-6;
  /// Timer anticipation: sleep until this long before each deadline, then spin to it, so the loop
  /// starts on time despite the platform's wake-up latency (costs wake_ahead/period of the core). 0: off.
  double loop_wake_ahead_s = 0.0;
  /// `wake_ahead_s: auto`: the loop runs its first second plainly, then anticipates by the median
  /// wake-up latency it measured (at most half a period).
  bool loop_wake_ahead_auto = false;
  RealtimeMode realtime = RealtimeMode::kPreferred;
  bool lock_memory = true;
  int cpu_dma_latency_us = 0;  ///< PM QoS request while running; −1: none
  ThreadPolicy loop_thread{true, 80, -1};
  ThreadPolicy receive_thread{true, 70, -1};
  ThreadPolicy publish_thread{false, 0, -1};
  double stale_timeout_s = 0.1;

  std::string lcm_url;  ///< empty: LCM's default (udpm://239.255.76.67:7667?ttl=0)
  std::string channel_prefix;
  double estimate_rate_Hz = 10.0;
  double measurement_rate_Hz = 100.0;
  double diagnostics_rate_Hz = 1.0;
  bool commands_enabled = false;

  TemperatureModel temperature;
  ValidityConfig validity;

  std::string state_file;  ///< empty: $STATE_DIRECTORY/estimates.json, else $XDG_STATE_HOME or ~/.local/state/rpemd/
  double state_write_interval_s = 5.0;
  double state_max_age_s = 3600.0;
  double status_interval_s = 1.0;  ///< a status line on stdout; 0: none
};

[[nodiscard]] DaemonConfig load_daemon_config(const std::string& path);
[[nodiscard]] DaemonConfig builtin_daemon_config();
/// The state file path after defaults.
[[nodiscard]] std::string resolve_state_file(const DaemonConfig& c);
[[nodiscard]] const std::string& builtin_demo_scenario_text();

}  // namespace rpem::daemon
