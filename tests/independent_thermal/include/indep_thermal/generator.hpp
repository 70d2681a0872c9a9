#pragma once
// One run: the plant integrated along a profile, sampled at the row rate, with what a drive would log
// (measured currents and voltage commands, speed, coolant and winding sensors) beside the truth. Rows are
// handed to a sink as they are made (a two-hour log at 1 kHz does not fit in memory) and kept only when asked.
#include <cstdint>
#include <functional>
#include <vector>

#include "indep_thermal/integrator.hpp"
#include "indep_thermal/machine.hpp"
#include "indep_thermal/parameters.hpp"
#include "indep_thermal/plant.hpp"
#include "indep_thermal/profile.hpp"

namespace indep_thermal {

struct Case {
  Machine machine;    // the configured machine: what the drive knows, and what the nominal plant is sized from
  Parameters params;  // the true plant
  Profile profile;
  CoolantMode coolant = CoolantMode::loop;
  std::uint64_t seed = 1;
  double duration_s = 7200.0;
  double rate_Hz = 2.0;
  StepControl control{1e-8, 1e-8, 0.25, kTemperatureStates};
  bool noise = true;      // false: the logged values are the true ones, unquantised
  bool averaged = false;  // log window means over [t_k−1, t_k] (the averaged log) instead of values at t_k
  bool keep_rows = true;  // keep every row in Result::rows
};

/// One row: the truth at t and what the log holds.
struct Row {
  Snapshot truth;
  double t_start_s = 0.0;   // start of the row's window, t_k−1 (t_0 for the first row)
  double stored_J = 0.0;    // Σ C_i·(T_i − T_i(0))
  double residual_J = 0.0;  // stored − (∫losses − ∫heat to coolant)
  // True means over the window [t_start, t] (at the first row, the values at t).
  double i_d_mean_A = 0.0;
  double i_q_mean_A = 0.0;
  double u_d_mean_V = 0.0;
  double u_q_mean_V = 0.0;
  double omega_el_mean_rad_s = 0.0;
  // Logged (measured) values: at t, or the window's means with Case::averaged.
  double i_d_A = 0.0;
  double i_q_A = 0.0;
  double u_d_V = 0.0;
  double u_q_V = 0.0;
  double omega_el_rad_s = 0.0;
  double t_winding_C = 0.0;
  double t_coolant_C = 0.0;
};

/// What a run leaves besides its rows.
struct Summary {
  std::size_t rows = 0;
  double t_winding_max_C = -1e300;
  double t_iron_max_C = -1e300;
  double t_magnet_max_C = -1e300;
  double t_coolant_min_C = 1e300;
  double t_coolant_max_C = -1e300;
  double e_losses_J = 0.0;
  double e_coolant_J = 0.0;
  double max_abs_residual_J = 0.0;
};

struct Result {
  std::vector<Row> rows;  // with Case::keep_rows
  Summary summary;
  StepStats stats;
};

using RowSink = std::function<void(const Row&)>;

/// Runs a case; each row goes to `sink` (if any) as it is made. Rows at t_k = k/rate_Hz,
/// k = 0 … ⌊duration·rate⌋. Throws UsageError for a bad case.
Result generate(const Case& c, const RowSink& sink = {});

/// The drive-cycle, heat-cool or file profile by name (`drive-cycle`, `heat-cool`, else a CSV path);
/// `load_scale` applies to the drive cycle.
Profile make_profile(const std::string& name, const Machine& machine, double duration_s, std::uint64_t seed,
                     double load_scale = 1.0);

}  // namespace indep_thermal
