#pragma once
// Drive logs with a known effect hidden in them, for the tests and the benchmark of `rpem diagnose` (the
// rpem::test_support library; not part of the product): a scenario (scenarios/diagnose-bench.yaml: a test-bench profile that gives every effect a chance to show;
// scenarios/diagnose-beckhoff.yaml: a motor on its measured flux map) with catalogue effects put into
// the simulated hardware.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "rpem/io/drive_log.hpp"
#include "rpem/sim/scenario.hpp"

namespace rpem::test {

/// One hidden effect with its true value, in the catalogue's terms (effects.hpp).
struct HiddenEffect {
  std::string name;                  ///< catalogue name, or "none"
  double value = 0.0;                ///< t_dead_s, offset_rad, offset_A, gain_error, ΔT [K], delay_s, r_fe_Ohm
  int phase = -1;                    ///< for current_offset and current_gain
  bool temperatures_logged = false;  ///< rs_drift, psim_drift: T columns in the log
};

/// Puts the effect into the scenario's hardware or machine.
void hide(sim::Scenario& s, const HiddenEffect& e);

/// Draws one effect of the catalogue with a realistic magnitude (docs/diagnose.md, "Hidden-effect
/// tests"): dead time 0.5–3 µs, θ offset 1–6°, sensor offset 0.5–3 % of rated current, gain error
/// 1–4 %, R_s drift of 20–60 K, ψm drift of 20–60 K, delay 15–60 µs, iron loss r_fe 20–60 pu.
[[nodiscard]] HiddenEffect draw_effect(std::mt19937_64& rng, const sim::Scenario& s, const std::string& name);

/// Simulates a scenario into drive-log rows (what `rpem sim` would write).
[[nodiscard]] std::vector<io::DriveLogRow> simulate(const sim::Scenario& s, io::DriveLogLayout* layout = nullptr);

}  // namespace rpem::test
