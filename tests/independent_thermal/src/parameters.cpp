#include "indep_thermal/parameters.hpp"

#include <cmath>

#include "indep_thermal/errors.hpp"
#include "indep_thermal/pi.hpp"
#include "indep_thermal/random.hpp"

namespace indep_thermal {

namespace {

// Volumetric heat capacities ρ·c [J/(m³·K)]: copper 8960·385, laminations 7650·460, aluminium 2700·900,
// rotor (laminations, magnets, shaft) 3.5e6.
constexpr double kRhoCCopper = 8960.0 * 385.0;
constexpr double kRhoCIron = 7650.0 * 460.0;
constexpr double kRhoCAluminium = 2700.0 * 900.0;
constexpr double kRhoCRotor = 3.5e6;
constexpr double kSteelConductivity_W_mK = 45.0;

// Design rules of the nominal plant (README.md, "Nominal parameters").
constexpr double kTorquePerRotorVolume_Nm_m3 = 20.0e3;  // liquid-cooled PMSM
constexpr double kStatorToRotorDiameter = 1.6;
constexpr double kCopperShareOfStatorAnnulus = 0.12;
constexpr double kIronShareOfStatorAnnulus = 0.55;
constexpr double kInsulationCapacityShare = 0.15;  // impregnation and liners, on top of the copper
constexpr double kWindingOverIronRise_K = 40.0;    // at the rated copper loss
constexpr double kIronOverCoolantRise_K = 45.0;    // at the rated copper and stator iron loss
constexpr double kLoopRise_K = 15.0;               // coolant over ambient at the rated losses
constexpr double kLoopTimeConstant_s = 600.0;

using E = CatalogueEntry;

}  // namespace

const std::vector<CatalogueEntry>& catalogue() {
  static const std::vector<CatalogueEntry> table = {
      {"electrical.r_s_reference_C", &Parameters::r_s_reference_C, "°C", Draw::fixed, 0, 0,
       "winding temperature at which R_s is the configuration's"},
      {"electrical.psi_m_reference_C", &Parameters::psi_m_reference_C, "°C", Draw::fixed, 0, 0,
       "magnet temperature at which ψm is the configuration's"},
      {"electrical.r_s_ref_Ohm", &Parameters::r_s_ref_Ohm, "Ω", Draw::electrical_factor, 0.9, 1.1,
       "R_s (DC) at the reference temperature"},
      {"electrical.psi_m_ref_Wb", &Parameters::psi_m_ref_Wb, "Wb", Draw::electrical_factor, 0.95, 1.05,
       "ψm at the reference temperature"},
      {"electrical.l_d_H", &Parameters::l_d_H, "H", Draw::electrical_factor, 0.95, 1.05, "L_d"},
      {"electrical.l_q_H", &Parameters::l_q_H, "H", Draw::electrical_factor, 0.95, 1.05, "L_q"},
      {"electrical.pole_pairs", &Parameters::pole_pairs, "1", Draw::fixed, 0, 0, "p"},
      {"copper.alpha20_per_K", &Parameters::copper_alpha20_per_K, "1/K", Draw::uniform, 3.82e-3, 3.93e-3,
       "copper's resistance coefficient at 20 °C (hard-drawn … annealed)"},
      {"copper.ac_factor_at_rated", &Parameters::ac_factor_at_rated, "1", Draw::uniform, 0.0, 0.15,
       "R_ac/R_dc − 1 at the rated electrical frequency (∝ f²)"},
      {"magnet.alpha20_per_K", &Parameters::magnet_alpha20_per_K, "1/K", Draw::uniform, -1.2e-3, -0.9e-3,
       "NdFeB remanence coefficient at 20 °C"},
      {"rated.frequency_Hz", &Parameters::rated_frequency_Hz, "Hz", Draw::fixed, 0, 0,
       "rated electrical frequency (loss laws' reference)"},
      {"rated.speed_rad_s", &Parameters::rated_speed_rad_s, "rad/s", Draw::fixed, 0, 0,
       "rated mechanical speed (loss laws' reference)"},
      {"rated.current_A", &Parameters::rated_current_A, "A", Draw::fixed, 0, 0, "rated peak phase current"},
      {"geometry.rotor_diameter_m", &Parameters::rotor_diameter_m, "m", Draw::factor, 0.87, 1.15,
       "rotor outer diameter D_r"},
      {"geometry.active_length_m", &Parameters::active_length_m, "m", Draw::factor, 0.8, 1.25, "stack length L"},
      {"geometry.airgap_m", &Parameters::airgap_m, "m", Draw::factor, 0.7, 1.4, "radial air gap g"},
      {"geometry.stator_outer_diameter_m", &Parameters::stator_outer_diameter_m, "m", Draw::factor, 0.92, 1.08,
       "stator outer diameter D_s"},
      {"geometry.endwinding_overhang_m", &Parameters::endwinding_overhang_m, "m", Draw::factor, 0.7, 1.4,
       "axial overhang of each end winding"},
      {"capacity.winding_J_K", &Parameters::c_winding_J_K, "J/K", Draw::factor, 0.8, 1.25, "winding (copper, insulation)"},
      {"capacity.iron_J_K", &Parameters::c_iron_J_K, "J/K", Draw::factor, 0.8, 1.25,
       "stator iron and the inner half of the housing"},
      {"capacity.rotor_J_K", &Parameters::c_rotor_J_K, "J/K", Draw::factor, 0.8, 1.25, "rotor iron, magnets, shaft"},
      {"conductance.winding_iron_W_K", &Parameters::g_winding_iron_W_K, "W/K", Draw::factor, 0.7, 1.4,
       "winding to stator iron through the slot liner"},
      {"conductance.iron_coolant_W_K", &Parameters::g_iron_coolant_W_K, "W/K", Draw::factor, 0.7, 1.4,
       "stator iron to coolant (housing contact, water jacket)"},
      {"conductance.shaft_W_K", &Parameters::g_shaft_W_K, "W/K", Draw::factor, 0.5, 2.0,
       "rotor to coolant through shaft and bearings"},
      {"endspace.k1_W_m2K", &Parameters::endspace_k1_W_m2K, "W/(m²·K)", Draw::factor, 0.7, 1.4, "end-space h at standstill"},
      {"endspace.k2", &Parameters::endspace_k2, "(s/m)^k3", Draw::factor, 0.5, 2.0, "end-space speed gain"},
      {"endspace.k3", &Parameters::endspace_k3, "1", Draw::uniform, 0.7, 1.0, "end-space speed exponent"},
      {"air.conductivity_W_mK", &Parameters::air_conductivity_W_mK, "W/(m·K)", Draw::fixed, 0, 0, "air at about 60 °C"},
      {"air.viscosity_m2_s", &Parameters::air_viscosity_m2_s, "m²/s", Draw::fixed, 0, 0,
       "kinematic viscosity of air at about 60 °C"},
      {"air.prandtl", &Parameters::air_prandtl, "1", Draw::fixed, 0, 0, "Prandtl number of air"},
      {"loss.stator_iron_rated_W", &Parameters::stator_iron_rated_W, "W", Draw::factor, 0.5, 2.0,
       "stator iron loss at rated frequency and flux ψm_ref"},
      {"loss.stator_hysteresis_share", &Parameters::stator_hysteresis_share, "1", Draw::uniform, 0.4, 0.7,
       "hysteresis share of it (∝ f·B^β)"},
      {"loss.stator_excess_share", &Parameters::stator_excess_share, "1", Draw::uniform, 0.0, 0.15,
       "excess share of it (∝ f^1.5·B^1.5); eddy (∝ f²·B²) the rest"},
      {"loss.steinmetz_exponent", &Parameters::steinmetz_exponent, "1", Draw::uniform, 1.6, 2.2, "β of the hysteresis term"},
      {"loss.rotor_iron_rated_W", &Parameters::rotor_iron_rated_W, "W", Draw::factor, 0.5, 2.0,
       "rotor iron loss at rated frequency and flux ψm_ref"},
      {"loss.rotor_hysteresis_share", &Parameters::rotor_hysteresis_share, "1", Draw::uniform, 0.1, 0.5,
       "hysteresis share of it; eddy the rest"},
      {"loss.magnet_rated_W", &Parameters::magnet_rated_W, "W", Draw::factor, 0.3, 3.0,
       "magnet eddy loss at rated frequency and rated current (∝ f²·|i|²)"},
      {"loss.mechanical_rated_W", &Parameters::mechanical_rated_W, "W", Draw::factor, 0.5, 2.0,
       "bearing friction and windage at rated speed (into the rotor)"},
      {"loss.bearing_share", &Parameters::bearing_share, "1", Draw::uniform, 0.2, 0.6,
       "bearing share of it (∝ n); windage (∝ n³) the rest"},
      {"coolant.start_C", &Parameters::coolant_start_C, "°C", Draw::uniform, 15.0, 30.0,
       "coolant (and ambient) temperature at t = 0"},
      {"coolant.loop_capacity_J_K", &Parameters::coolant_loop_capacity_J_K, "J/K", Draw::factor, 0.5, 2.0,
       "heat capacity of the coolant loop (loop mode)"},
      {"coolant.radiator_W_K", &Parameters::coolant_radiator_W_K, "W/K", Draw::factor, 0.7, 1.4,
       "loop to ambient (loop mode)"},
      {"coolant.other_heat_share", &Parameters::coolant_other_heat_share, "1", Draw::uniform, 0.2, 1.0,
       "other heat on the loop as a share of the machine's losses (loop mode)"},
      {"sensor.winding_tau_s", &Parameters::sensor_winding_tau_s, "s", Draw::uniform, 3.0, 20.0,
       "time constant of the winding sensor"},
      {"sensor.winding_noise_K", &Parameters::sensor_winding_noise_K, "K", Draw::fixed, 0, 0, "σ of the winding sensor"},
      {"sensor.winding_resolution_K", &Parameters::sensor_winding_resolution_K, "K", Draw::fixed, 0, 0,
       "quantum of the winding sensor (0: none)"},
      {"sensor.placement_gain", &Parameters::sensor_placement_gain, "1", Draw::fixed, 0, 0,
       "the sensor reads T_c + gain·(T_lag − T_c)"},
      {"sensor.coolant_noise_K", &Parameters::sensor_coolant_noise_K, "K", Draw::fixed, 0, 0, "σ of the coolant sensor"},
      {"sensor.coolant_resolution_K", &Parameters::sensor_coolant_resolution_K, "K", Draw::fixed, 0, 0,
       "quantum of the coolant sensor (0: none)"},
      {"noise.current_rel", &Parameters::noise_current_rel, "1", Draw::fixed, 0, 0,
       "σ of i_d, i_q per row over the rated peak current"},
      {"noise.voltage_rel", &Parameters::noise_voltage_rel, "1", Draw::fixed, 0, 0,
       "σ of u_d, u_q per row over the rated peak phase voltage"},
      {"drive.voltage_limit_rel", &Parameters::voltage_limit_rel, "1", Draw::fixed, 0, 0,
       "field weakening holds |u| at this share of the rated peak phase voltage"},
      {"drive.current_limit_rel", &Parameters::current_limit_rel, "1", Draw::fixed, 0, 0,
       "|i| limit over the rated peak current"},
      {"drive.derate_start_C", &Parameters::derate_start_C, "°C", Draw::fixed, 0, 0,
       "winding sensor temperature where i_q starts to be derated"},
      {"drive.derate_end_C", &Parameters::derate_end_C, "°C", Draw::fixed, 0, 0,
       "winding sensor temperature where i_q reaches 0"},
      {"initial.rise_K", &Parameters::initial_rise_K, "K", Draw::fixed, 0, 0,
       "every node starts this much above the coolant"},
  };
  return table;
}

double rated_copper_loss_W(const Parameters& p) { return 1.5 * p.r_s_ref_Ohm * p.rated_current_A * p.rated_current_A; }

Parameters nominal_parameters(const Machine& m) {
  Parameters p;
  p.r_s_reference_C = 20.0;
  p.psi_m_reference_C = 20.0;
  p.r_s_ref_Ohm = m.r_s_Ohm;
  p.psi_m_ref_Wb = m.psi_m_Wb;
  p.l_d_H = m.l_d_H;
  p.l_q_H = m.l_q_H;
  p.pole_pairs = m.pole_pairs;
  p.rated_frequency_Hz = m.omega_el_rated_rad_s() / (2.0 * kPi);
  p.rated_speed_rad_s = m.omega_mech_rated_rad_s();
  p.rated_current_A = m.peak_current_A();

  // Geometry from the rated torque: rotor volume T_n/TRV, L = D_r.
  const double rotor_volume_m3 = m.rated_torque_Nm() / kTorquePerRotorVolume_Nm_m3;
  const double d_r = std::cbrt(4.0 * rotor_volume_m3 / kPi);
  const double len = d_r;
  const double d_s = kStatorToRotorDiameter * d_r;
  p.rotor_diameter_m = d_r;
  p.active_length_m = len;
  p.stator_outer_diameter_m = d_s;
  p.airgap_m = 1e-3 * (0.2 + 2.0 * std::sqrt(d_r * len));  // g [mm] = 0.2 + 2·√(D·L) [m]
  p.endwinding_overhang_m = 0.25 * len;

  // Heat capacities from the volumes.
  const double annulus_m3 = kPi / 4.0 * (d_s * d_s - d_r * d_r) * len;
  p.c_winding_J_K = (1.0 + kInsulationCapacityShare) * kRhoCCopper * kCopperShareOfStatorAnnulus * annulus_m3 *
                    (1.0 + p.endwinding_overhang_m / len);
  const double housing_m3 = kPi * d_s * (0.08 * d_s) * (1.3 * len);
  p.c_iron_J_K = kRhoCIron * kIronShareOfStatorAnnulus * annulus_m3 + 0.5 * kRhoCAluminium * housing_m3;
  const double d_shaft = 0.35 * d_r;
  const double shaft_ends_m3 = 2.0 * kPi / 4.0 * d_shaft * d_shaft * (0.5 * len);
  p.c_rotor_J_K = kRhoCRotor * (0.9 * kPi / 4.0 * d_r * d_r * len + shaft_ends_m3);

  // Losses at the rated point, as shares of the rated power.
  const double p_n = m.rated_power_W();
  p.stator_iron_rated_W = 0.012 * p_n;
  p.rotor_iron_rated_W = 0.004 * p_n;
  p.magnet_rated_W = 0.005 * p_n;
  p.mechanical_rated_W = 0.004 * p_n;

  // Conduction paths sized for the design rises at the rated losses; the shaft from its geometry.
  const double p_cu_n = rated_copper_loss_W(p);
  p.g_winding_iron_W_K = p_cu_n / kWindingOverIronRise_K;
  p.g_iron_coolant_W_K = (p_cu_n + p.stator_iron_rated_W) / kIronOverCoolantRise_K;
  p.g_shaft_W_K = kSteelConductivity_W_mK * kPi / 4.0 * d_shaft * d_shaft / (0.5 * len);

  // Coolant loop: the rated losses plus the other heat raise it kLoopRise_K over ambient.
  const double p_loss_n = p_cu_n + p.stator_iron_rated_W + p.rotor_iron_rated_W + p.magnet_rated_W + p.mechanical_rated_W;
  p.coolant_radiator_W_K = (1.0 + p.coolant_other_heat_share) * p_loss_n / kLoopRise_K;
  p.coolant_loop_capacity_J_K = p.coolant_radiator_W_K * kLoopTimeConstant_s;
  return p;
}

Parameters draw_parameters(const Machine& machine, std::uint64_t seed, DrawOptions options) {
  Parameters p = nominal_parameters(machine);
  Rng rng(seed, Stream::parameters);
  Rng electrical(seed, Stream::electrical);
  for (const CatalogueEntry& e : catalogue()) {
    double& x = p.*e.field;
    switch (e.draw) {
      case Draw::fixed:
        break;
      case Draw::factor:
        x *= rng.log_uniform(e.lo, e.hi);
        break;
      case Draw::uniform:
        x = rng.uniform(e.lo, e.hi);
        break;
      case Draw::electrical_factor: {
        const double f = electrical.log_uniform(e.lo, e.hi);  // drawn always: the stream does not shift
        if (options.electrical) x *= f;
        break;
      }
    }
  }
  validate(p);
  return p;
}

namespace {

const CatalogueEntry* find(const std::string& key) {
  for (const CatalogueEntry& e : catalogue()) {
    if (key == e.key) return &e;
  }
  return nullptr;
}

[[noreturn]] void unknown_key(const std::string& key) {
  std::string known;
  for (const CatalogueEntry& e : catalogue()) known += std::string(known.empty() ? "" : ", ") + e.key;
  throw UsageError("unknown parameter '" + key + "' (known: " + known + ")");
}

}  // namespace

void set_parameter(Parameters& p, const std::string& key, double value) {
  const CatalogueEntry* e = find(key);
  if (e == nullptr) unknown_key(key);
  if (!std::isfinite(value)) throw UsageError("parameter " + key + ": value is not finite");
  p.*(e->field) = value;
}

double get_parameter(const Parameters& p, const std::string& key) {
  const CatalogueEntry* e = find(key);
  if (e == nullptr) unknown_key(key);
  return p.*(e->field);
}

void validate(const Parameters& p) {
  auto require = [](bool ok, const char* key, const char* why) {
    if (!ok) throw UsageError(std::string("parameter ") + key + ": " + why);
  };
  for (const CatalogueEntry& e : catalogue()) {
    require(std::isfinite(p.*e.field), e.key, "not finite");
  }
  require(p.r_s_ref_Ohm > 0, "electrical.r_s_ref_Ohm", "must be > 0");
  require(p.psi_m_ref_Wb > 0, "electrical.psi_m_ref_Wb", "must be > 0");
  require(p.l_d_H > 0, "electrical.l_d_H", "must be > 0");
  require(p.l_q_H > 0, "electrical.l_q_H", "must be > 0");
  require(p.pole_pairs >= 1 && p.pole_pairs == std::floor(p.pole_pairs), "electrical.pole_pairs",
          "must be a whole number >= 1");
  // Copper's resistance reaches 0 at −1/α + 20 °C; the law is meant for windings above −100 °C.
  require(p.copper_alpha20_per_K > 0 && p.copper_alpha20_per_K < 1.0 / 120.0, "copper.alpha20_per_K",
          "must be in (0, 1/120) per K");
  require(p.magnet_alpha20_per_K > -5e-3 && p.magnet_alpha20_per_K <= 0, "magnet.alpha20_per_K",
          "must be in (-5e-3, 0] per K");
  require(p.ac_factor_at_rated >= 0, "copper.ac_factor_at_rated", "must be >= 0");
  require(p.rated_frequency_Hz > 0, "rated.frequency_Hz", "must be > 0");
  require(p.rated_speed_rad_s > 0, "rated.speed_rad_s", "must be > 0");
  require(p.rated_current_A > 0, "rated.current_A", "must be > 0");
  require(p.rotor_diameter_m > 0, "geometry.rotor_diameter_m", "must be > 0");
  require(p.active_length_m > 0, "geometry.active_length_m", "must be > 0");
  require(p.airgap_m > 0 && p.airgap_m < 0.1 * p.rotor_diameter_m, "geometry.airgap_m", "must be in (0, D_r/10)");
  require(p.stator_outer_diameter_m > p.rotor_diameter_m + 2.0 * p.airgap_m, "geometry.stator_outer_diameter_m",
          "must exceed D_r + 2·g");
  require(p.endwinding_overhang_m > 0, "geometry.endwinding_overhang_m", "must be > 0");
  require(p.c_winding_J_K > 0, "capacity.winding_J_K", "must be > 0");
  require(p.c_iron_J_K > 0, "capacity.iron_J_K", "must be > 0");
  require(p.c_rotor_J_K > 0, "capacity.rotor_J_K", "must be > 0");
  require(p.g_winding_iron_W_K > 0, "conductance.winding_iron_W_K", "must be > 0");
  require(p.g_iron_coolant_W_K > 0, "conductance.iron_coolant_W_K", "must be > 0");
  require(p.g_shaft_W_K > 0, "conductance.shaft_W_K", "must be > 0");
  require(p.endspace_k1_W_m2K > 0, "endspace.k1_W_m2K", "must be > 0");
  require(p.endspace_k2 >= 0, "endspace.k2", "must be >= 0");
  require(p.endspace_k3 > 0, "endspace.k3", "must be > 0");
  require(p.air_conductivity_W_mK > 0, "air.conductivity_W_mK", "must be > 0");
  require(p.air_viscosity_m2_s > 0, "air.viscosity_m2_s", "must be > 0");
  require(p.air_prandtl > 0, "air.prandtl", "must be > 0");
  require(p.stator_iron_rated_W >= 0, "loss.stator_iron_rated_W", "must be >= 0");
  require(
      p.stator_hysteresis_share >= 0 && p.stator_excess_share >= 0 && p.stator_hysteresis_share + p.stator_excess_share <= 1,
      "loss.stator_hysteresis_share", "with loss.stator_excess_share: shares >= 0 summing to <= 1");
  require(p.steinmetz_exponent > 0, "loss.steinmetz_exponent", "must be > 0");
  require(p.rotor_iron_rated_W >= 0, "loss.rotor_iron_rated_W", "must be >= 0");
  require(p.rotor_hysteresis_share >= 0 && p.rotor_hysteresis_share <= 1, "loss.rotor_hysteresis_share",
          "must be in [0, 1]");
  require(p.magnet_rated_W >= 0, "loss.magnet_rated_W", "must be >= 0");
  require(p.mechanical_rated_W >= 0, "loss.mechanical_rated_W", "must be >= 0");
  require(p.bearing_share >= 0 && p.bearing_share <= 1, "loss.bearing_share", "must be in [0, 1]");
  require(p.coolant_start_C > -60 && p.coolant_start_C < 150, "coolant.start_C", "must be in (-60, 150) °C");
  require(p.coolant_loop_capacity_J_K > 0, "coolant.loop_capacity_J_K", "must be > 0");
  require(p.coolant_radiator_W_K > 0, "coolant.radiator_W_K", "must be > 0");
  require(p.coolant_other_heat_share >= 0, "coolant.other_heat_share", "must be >= 0");
  require(p.sensor_winding_tau_s > 0, "sensor.winding_tau_s", "must be > 0");
  require(p.sensor_winding_noise_K >= 0, "sensor.winding_noise_K", "must be >= 0");
  require(p.sensor_winding_resolution_K >= 0, "sensor.winding_resolution_K", "must be >= 0");
  require(p.sensor_placement_gain > 0, "sensor.placement_gain", "must be > 0");
  require(p.sensor_coolant_noise_K >= 0, "sensor.coolant_noise_K", "must be >= 0");
  require(p.sensor_coolant_resolution_K >= 0, "sensor.coolant_resolution_K", "must be >= 0");
  require(p.noise_current_rel >= 0, "noise.current_rel", "must be >= 0");
  require(p.noise_voltage_rel >= 0, "noise.voltage_rel", "must be >= 0");
  require(p.voltage_limit_rel > 0, "drive.voltage_limit_rel", "must be > 0");
  require(p.current_limit_rel > 0, "drive.current_limit_rel", "must be > 0");
  require(p.derate_end_C > p.derate_start_C, "drive.derate_end_C", "must exceed drive.derate_start_C");
  require(p.initial_rise_K >= 0, "initial.rise_K", "must be >= 0");
}

}  // namespace indep_thermal
