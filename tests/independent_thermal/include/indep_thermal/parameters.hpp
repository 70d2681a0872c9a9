#pragma once
// Every number of the plant, in one flat struct, and the one table (catalogue) that names each with its unit,
// its meaning and how it is drawn off its nominal value. The nominal values are sized from the configured
// machine by the design rules of nominal_parameters() (README.md, "Nominal parameters").
#include <cstdint>
#include <string>
#include <vector>

#include "indep_thermal/machine.hpp"

namespace indep_thermal {

struct Parameters {
  // Electrical: R_s at its reference temperature, ψm at its own (default: the configuration's values at 20 °C).
  double r_s_reference_C = 20.0;
  double psi_m_reference_C = 20.0;
  double r_s_ref_Ohm = 0.0;
  double psi_m_ref_Wb = 0.0;
  double l_d_H = 0.0;
  double l_q_H = 0.0;
  double pole_pairs = 0.0;
  // Materials.
  double copper_alpha20_per_K = 3.93e-3;  // dR/dT / R at 20 °C
  double magnet_alpha20_per_K = -1.1e-3;  // dBr/dT / Br at 20 °C
  double ac_factor_at_rated = 0.05;       // R_ac/R_dc − 1 at the rated electrical frequency
  // Rated references of the loss laws.
  double rated_frequency_Hz = 0.0;  // electrical
  double rated_speed_rad_s = 0.0;   // mechanical
  double rated_current_A = 0.0;     // peak phase
  // Geometry (inner rotor, water-jacket-cooled stator).
  double rotor_diameter_m = 0.0;
  double active_length_m = 0.0;
  double airgap_m = 0.0;
  double stator_outer_diameter_m = 0.0;
  double endwinding_overhang_m = 0.0;
  // Heat capacities.
  double c_winding_J_K = 0.0;
  double c_iron_J_K = 0.0;
  double c_rotor_J_K = 0.0;
  // Conduction paths.
  double g_winding_iron_W_K = 0.0;  // slot liner and impregnation
  double g_iron_coolant_W_K = 0.0;  // lamination-housing contact and water jacket
  double g_shaft_W_K = 0.0;         // rotor - shaft - bearings - housing
  // End-space convection h = k1·(1 + k2·v^k3), v the rotor's peripheral speed [m/s].
  double endspace_k1_W_m2K = 15.0;
  double endspace_k2 = 0.4;
  double endspace_k3 = 0.9;
  // Air in the gap and the end space (constant properties, air at about 60 °C).
  double air_conductivity_W_mK = 0.0287;
  double air_viscosity_m2_s = 1.9e-5;
  double air_prandtl = 0.70;
  // Losses at the rated point (rated electrical frequency, flux = ψm_ref, rated peak current, rated speed).
  double stator_iron_rated_W = 0.0;
  double stator_hysteresis_share = 0.55;
  double stator_excess_share = 0.08;
  double steinmetz_exponent = 1.8;
  double rotor_iron_rated_W = 0.0;
  double rotor_hysteresis_share = 0.3;
  double magnet_rated_W = 0.0;
  double mechanical_rated_W = 0.0;
  double bearing_share = 0.4;
  // Coolant loop (used in the `loop` coolant mode; `constant` holds coolant_start_C).
  double coolant_start_C = 20.0;
  double coolant_loop_capacity_J_K = 0.0;
  double coolant_radiator_W_K = 0.0;
  double coolant_other_heat_share = 0.5;  // other heat on the loop (inverter) as a share of the machine's losses
  // Sensors and measurement noise.
  double sensor_winding_tau_s = 8.0;
  double sensor_winding_noise_K = 0.2;
  double sensor_winding_resolution_K = 0.1;
  double sensor_placement_gain = 1.0;  // the sensor reads T_c + gain·(T_lag − T_c)
  double sensor_coolant_noise_K = 0.1;
  double sensor_coolant_resolution_K = 0.1;
  double noise_current_rel = 1e-3;  // σ of i_d, i_q per row, relative to the rated peak current
  double noise_voltage_rel = 5e-4;  // σ of u_d, u_q per row, relative to the rated peak phase voltage
  // The drive: voltage and current limits, thermal derating on the winding sensor.
  double voltage_limit_rel = 0.95;  // of the rated peak phase voltage
  double current_limit_rel = 1.5;   // of the rated peak current
  double derate_start_C = 150.0;
  double derate_end_C = 180.0;
  // Initial state: every node and the coolant start at coolant_start_C + initial_rise_K (coolant: + 0).
  double initial_rise_K = 0.0;
};

/// How a parameter is drawn off its nominal value x0 (catalogue `lo`, `hi`).
enum class Draw {
  fixed,              // x0
  factor,             // x0·f, f log-uniform in [lo, hi]
  uniform,            // uniform in [lo, hi] (absolute)
  electrical_factor,  // like factor, but only with DrawOptions::electrical (otherwise fixed)
};

struct CatalogueEntry {
  const char* key;
  double Parameters::*field;
  const char* unit;
  Draw draw;
  double lo;
  double hi;
  const char* meaning;
};

/// The one table of parameters: keys for --set, the draw of each, units and meanings.
const std::vector<CatalogueEntry>& catalogue();

/// The nominal plant of a configured machine (README.md, "Nominal parameters").
Parameters nominal_parameters(const Machine& machine);

struct DrawOptions {
  bool electrical = false;  // draw R_s, ψm, L_d, L_q off the configuration too
};

/// The nominal plant drawn per the catalogue from `seed` (its own random stream).
Parameters draw_parameters(const Machine& machine, std::uint64_t seed, DrawOptions options = {});

/// Sets one parameter by key; throws UsageError for an unknown key (listing the known) or a non-finite value.
void set_parameter(Parameters& p, const std::string& key, double value);
/// The value of one parameter by key; throws UsageError for an unknown key.
double get_parameter(const Parameters& p, const std::string& key);

/// Checks the invariants the plant relies on (positive capacities and conductances, shares in [0, 1],
/// geometry that fits); throws UsageError naming the key and why.
void validate(const Parameters& p);

/// Copper loss 1.5·R_s·Î² at the rated peak current and the reference temperature [W] (amplitude-invariant dq).
double rated_copper_loss_W(const Parameters& p);

}  // namespace indep_thermal
