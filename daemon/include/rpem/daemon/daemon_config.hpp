#pragma once
// rpemd's configuration (docs/rpemd.md, examples in config/): an optional `daemon` section beside the
// machine configuration sections (`machine`, `estimator`, `model_extensions`) — so a machine file such
// as `rpem diagnose`'s extended.yaml is also a complete rpemd configuration — or
// `daemon.machine_config` pointing at one. Strict: unknown keys and out-of-range values are errors
// (ConfigError; rpemd exits 78).
//
// Two parts: LiveConfig is what SIGHUP reloads — the control thread sends it to the loop as one object
// and checks commands against it; FixedConfig is what only a restart applies (a reload whose file
// changes it is refused and counted).

#include <cstdint>
#include <string>
#include <vector>

#include "rpem/core/thermal.hpp"
#include "rpem/core/thermal_fusion.hpp"
#include "rpem/daemon/realtime.hpp"
#include "rpem/daemon/source_catalogue.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::daemon {

enum class RealtimeMode { kRequired, kPreferred, kOff };

/// Winding and magnet temperatures from r̂s and ψ̂m: the inverse of the drift laws (core/thermal.hpp);
/// value_ref defaults to the machine's offline r_s and ψm.
using TemperatureModel = core::ThermalModel;

/// When an estimate is valid (docs/rpemd.md, "Validity and age"). A parameter is identified after
/// adapting long enough (r_s: this much adaptation in all; ψm: this long without a pause), and valid
/// while identified and its last adaptation is at most max_hold_s old.
struct ValidityConfig {
  double r_s_after_s = 2.0;
  double psi_m_after_s = 1.0;
  double max_hold_s = 20.0;
  double convergence_window_s = 2.0;
  double convergence_band = 0.002;  ///< relative spread over the window
};

/// Whether RPEM_COMMAND must be authenticated (docs/rpemd.md, "Authentication"). `none` is accepted
/// only where LCM cannot leave the host (lcm_is_local).
enum class CommandAuthentication : std::uint8_t { kRequired, kNone };

/// What SIGHUP reloads.
struct LiveConfig {
  io::MachineConfig machine;
  TemperatureModel temperature;
  ValidityConfig validity;
  /// The thermal network and its filter (docs/thermal.md, "In rpemd"): a top-level `thermal` section or the
  /// file `daemon.thermal_config` names (what `rpem thermal fit` writes). Without either, no fusion runs.
  bool thermal_active = false;
  core::ThermalFusionConfig thermal;
  bool commands_enabled = false;
  CommandAuthentication command_authentication = CommandAuthentication::kRequired;
};

struct LoopConfig {
  double period_s = 125e-6;
  /// Timer anticipation: sleep until this long before each deadline, then spin to it, so the loop
  /// starts on time despite the platform's wake-up latency (costs wake_ahead/period of the core). 0: off.
  double wake_ahead_s = 0.0;
  /// `wake_ahead_s: auto`: the loop runs its first second plainly, then anticipates by the median
  /// wake-up latency it measured (at most half a period).
  bool wake_ahead_auto = false;
  RealtimeMode realtime = RealtimeMode::kPreferred;
  bool lock_memory = true;
  int cpu_dma_latency_us = 0;  ///< PM QoS request while running; −1: none
  ThreadPolicy thread{true, 80, -1};
  double stale_timeout_s = 0.1;  ///< daemon.stale_timeout_s
  bool operator==(const LoopConfig&) const = default;
};

struct LcmConfig {
  std::string url;  ///< empty: LCM's default (udpm://239.255.76.67:7667?ttl=0)
  std::string channel_prefix;
  double estimate_rate_Hz = 10.0;
  double measurement_rate_Hz = 100.0;
  double diagnostics_rate_Hz = 1.0;
  bool operator==(const LcmConfig&) const = default;
};

struct StateConfig {
  std::string file;  ///< empty: $STATE_DIRECTORY/estimates.json, else $XDG_STATE_HOME or ~/.local/state/rpemd/
  double write_interval_s = 5.0;
  double max_age_s = 3600.0;
  bool operator==(const StateConfig&) const = default;
};

/// What only a restart applies.
struct FixedConfig {
  SourceConfig source;
  LoopConfig loop;
  ThreadPolicy receive_thread{true, 70, -1};  ///< the source's thread
  ThreadPolicy publish_thread{false, 0, -1};
  LcmConfig lcm;
  StateConfig state;
  double status_interval_s = 1.0;  ///< a status line on stdout; 0: none
  bool operator==(const FixedConfig&) const = default;
};

struct DaemonConfig {
  std::string source_file;  ///< where it was loaded from ("<built-in>")
  LiveConfig live;
  FixedConfig fixed;
  /// What the configuration leaves to an assumption a user should know of (io::assumed_law_notes: a magnet law
  /// taken from the machine's ψm at 20 °C, a copper law's reference temperature); rpemd says each at start.
  std::vector<std::string> notes;
};

[[nodiscard]] DaemonConfig load_daemon_config(const std::string& path);
[[nodiscard]] DaemonConfig builtin_daemon_config();
/// The state file path after defaults.
[[nodiscard]] std::string resolve_state_file(const StateConfig& c);
/// The LCM URL rpemd uses: `url`, or LCM's own default ($LCM_DEFAULT_URL, else udpm with ttl 0).
[[nodiscard]] std::string effective_lcm_url(const std::string& url);
/// True if messages on `url` cannot leave the host: memq://, or udpm:// with ttl 0 (LCM's default ttl).
[[nodiscard]] bool lcm_is_local(const std::string& url);
/// The first part of `b` a restart would change relative to `a` ("source", "loop", …), or "" if none.
[[nodiscard]] const char* fixed_difference(const FixedConfig& a, const FixedConfig& b);

}  // namespace rpem::daemon
