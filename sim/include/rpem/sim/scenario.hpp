#pragma once
// A simulation scenario (docs/scenarios.md): the machine, inverter, plant, control, sensors, and
// the time-varying quantities with their events. Loaded from YAML with the strict reader.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rpem/io/machine_config.hpp"
#include "rpem/sim/foc.hpp"
#include "rpem/sim/inverter.hpp"
#include "rpem/sim/plant.hpp"
#include "rpem/sim/regime.hpp"
#include "rpem/sim/sensors.hpp"
#include "rpem/sim/signal.hpp"
#include "rpem/sim/thermal_plant.hpp"

namespace rpem::sim {

/// Quantities a scenario can change over time.
enum class Quantity : int {
  kPsiM = 0,    ///< psi_m_Wb — magnet flux at the thermal reference temperature
  kRs,          ///< r_s_Ohm — stator resistance at the thermal reference temperature
  kLd,          ///< l_d_H (constant-inductance magnetics)
  kLq,          ///< l_q_H
  kSpeed,       ///< speed_rpm — imposed (dynamometer) or reference (speed control), mechanical
  kTorque,      ///< torque_Nm — command (torque control) or load (inertia mechanics)
  kUdc,         ///< u_dc_V
  kTWinding,    ///< t_winding_C
  kTMagnet,     ///< t_magnet_C
  kLoadTorque,  ///< load_torque_Nm — inertia mechanics' load, when the scenario gives it (else torque_Nm)
  kCount
};
inline constexpr std::array<const char*, static_cast<int>(Quantity::kCount)> kQuantityNames = {
    "psi_m_Wb",  "r_s_Ohm", "l_d_H",       "l_q_H",      "speed_rpm",
    "torque_Nm", "u_dc_V",  "t_winding_C", "t_magnet_C", "load_torque_Nm"};

/// How the plant is integrated at switching fidelity (docs/scenarios.md, `plant.integrator`): from one
/// switching instant to the next (EdgeIntegrator), or in fixed steps of Heun's method with the
/// inverter's mean voltage over each step. Averaged fidelity always takes fixed steps.
enum class PlantIntegrator { kEdges, kFixedStep };

struct LogOptions {
  bool dq_columns = false;
  bool temperatures = false;
  bool torque_cmd = false;
};

/// The emulated VESC's configuration where its replies show it (`vesc:`; defaults of vedderb/bldc
/// motor/mcconf_default.h): COMM_GET_VALUES_SETUP's speed, distance and battery level (sim/vesc_tool_session.hpp).
struct VescConfig {
  double wheel_diameter_m = 0.083;  ///< si_wheel_diameter
  double gear_ratio = 3.0;          ///< si_gear_ratio
  int battery_cells = 3;            ///< si_battery_cells, Li-ion 3.0–4.2 V (si_battery_type's default)
  double battery_Ah = 6.0;          ///< si_battery_ah
};

struct Scenario {
  std::string name;
  std::string source;         ///< file it was loaded from
  io::MachineConfig machine;  ///< nominal machine + estimator settings
  double duration_s = 1.0;
  double warmup_s = 0.2;            ///< simulated before t = 0, not logged
  double sample_period_s = 125e-6;  ///< control and logging period (PWM double update)
  std::uint64_t seed = 1;
  InverterConfig inverter;
  double inverter_delay_s = 0.0;                         ///< the command acts this much late, < one period (hidden effect)
  PlantIntegrator integrator = PlantIntegrator::kEdges;  ///< switching fidelity only
  double plant_step_s = 1e-6;                            ///< the fixed-step integrator's step
  double plant_tolerance = 1e-9;                         ///< edges with a flux map: relative local error per step
  std::string flux_map_file;                             ///< empty: constant inductances
  MechanicsConfig mechanics;
  FocConfig control;
  SensorConfig sensors;
  /// Temperature coupling (core/thermal.hpp): r_s and ψm signals are the values at the laws' reference
  /// temperature; the laws' value_ref is unused.
  core::ThermalModel thermal;
  /// Temperatures from the machine's losses (`thermal_plant:`); when enabled, t_winding_C and t_magnet_C are
  /// its state, not signals.
  ThermalPlantConfig thermal_plant;
  double r_fe_Ohm = 0.0;  ///< iron-loss resistance; 0: none (hidden effect)
  std::array<Signal, static_cast<int>(Quantity::kCount)> signals;
  /// Inertia mechanics: the load is load_torque_Nm (given in `initial` or by an event) rather than torque_Nm.
  bool separate_load = false;
  /// What the controller does with the bridge over time (empty: closed loop throughout).
  std::vector<RegimeEvent> regimes;
  VescConfig vesc;
  LogOptions log;

  [[nodiscard]] Signal& signal(Quantity q) { return signals[static_cast<std::size_t>(q)]; }
  [[nodiscard]] const Signal& signal(Quantity q) const { return signals[static_cast<std::size_t>(q)]; }
};

/// Loads a scenario file. `machine` is resolved relative to the scenario's directory, or
/// "builtin:paper-ipmsm" for the compiled-in configuration.
[[nodiscard]] Scenario load_scenario(const std::string& path);
/// Parses scenario text (`name` stands for the file name in messages; relative paths resolve from
/// `base_dir`).
[[nodiscard]] Scenario parse_scenario(const std::string& text, const std::string& name, const std::string& base_dir);

/// A scenario with the defaults of the paper's setup (tab_machineData): built-in machine, switching
/// inverter at 4 kHz with 3rd-harmonic injection, edge-to-edge plant, 125 µs control, dynamometer,
/// torque mode.
[[nodiscard]] Scenario paper_scenario();

}  // namespace rpem::sim
