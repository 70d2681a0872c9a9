#pragma once
// `rpem sim --vesc IFACE --controller-id N`: the simulated drive answers on a SocketCAN interface as a VESC
// does (docs/can-vesc.md, "Emulator"). Physics: sim/vesc_motor.hpp; drive time on demand:
// sim/vesc_on_demand.hpp; protocol: can/vesc_firmware.hpp; this file only moves frames and time stamps.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "rpem/sim/scenario.hpp"

namespace rpem::tools {

struct VescEmulatorOptions {
  std::string interface;
  int controller_id = 0;
  double temp_fet_C = 40.0;
  double status_rate_1_Hz = 50.0;      ///< app_configuration can_status_rate_1 (appconf_default.h: 50)
  std::uint32_t status_msgs_1 = 0x19;  ///< can_status_msgs_r1 bit k: status k+1 (1, 4, 5 by default here)
  double status_rate_2_Hz = 5.0;       ///< can_status_rate_2 (appconf_default.h: 5)
  std::uint32_t status_msgs_2 = 0x26;  ///< statuses 2, 3, 6
  double silent_at_s = -1.0;           ///< go silent (answer nothing, broadcast nothing) at this time…
  double silent_for_s = 0.0;           ///< …for this long; SIGUSR1 also toggles silence
  double duration_s = 0.0;             ///< stop after this long (0: the scenario's duration)
  /// While no poll is pending: run the drive ahead this much drive time per look at the socket, and wait up
  /// to this long for a poll between looks (docs/can-vesc.md, "Drive time, on demand").
  double idle_step_s = 1.0e-3;
  std::string truth;  ///< also write the true state every 10 ms (sim/truth_log.hpp)
};

void add_vesc_emulator_options(CLI::App* cmd, VescEmulatorOptions& options);

/// Runs the emulated VESC until the scenario ends, `duration_s` passes, or SIGINT/SIGTERM.
int run_vesc_emulator(sim::Scenario scenario, const VescEmulatorOptions& options);

}  // namespace rpem::tools
