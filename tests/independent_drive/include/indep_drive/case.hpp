#pragma once
// A case: everything the generator needs, in SI (README "API"). Fields set to kAuto take the default
// derived from the machine that README "Defaults" gives; resolve_defaults() fills them in.
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "indep_drive/inverter.hpp"
#include "indep_drive/machine_config.hpp"
#include "indep_drive/plant.hpp"
#include "indep_drive/profile.hpp"

namespace indep {

inline constexpr double kAuto = std::numeric_limits<double>::quiet_NaN();

/// The true machine: each parameter uniformly within ± span of the configured value, or a fixed offset.
struct MachineDraw {
  double psi_m_span_rel = 0.08;
  double r_s_span_rel = 0.25;
  double l_span_rel = 0.05;                                    // L_d and L_q, drawn independently
  std::optional<double> psi_m_rel, r_s_rel, l_d_rel, l_q_rel;  // fixed true/configured − 1 instead of a draw
};

struct DeadTimeParams {
  bool on = false;
  double t_dead_s = 2e-6;
  double v_device_V = kAuto;  // 0.002·u_dc
  double i_band_A = kAuto;    // 0.03·√2·I_n
};
struct DelayParams {
  bool on = false;
  double delay_s = kAuto;  // one control period
  double periods = kAuto;  // alternatively in control periods (wins over delay_s when set)
};
struct ThetaOffsetParams {
  bool on = false;
  double offset_rad = 0.05235987755982988;  // 3°, θ_true = θ_logged + offset_rad
};
/// A current sensor error per phase (a, b, c).
struct PhaseErrorParams {
  bool on = false;
  std::array<double, 3> value{};
};
struct SaturationParams {
  bool ld = false, lq = false, cross = false;
  std::string map_path;                 // "" : data/beckhoff-am8141-flux-maps/..._400rpm.csv of the source tree
  double full_scale_current_A = kAuto;  // the map's largest |i_q| lands here; √2·I_n
  double depth = 1.0;                   // multiplies the map's nonlinearity
  int degree = 4;
  [[nodiscard]] bool any() const { return ld || lq || cross; }
};
struct HarmonicParams {
  bool on = false;
  HarmonicPair pair;
};
struct IronLossParams {
  bool on = false;
  double r_fe_Ohm = kAuto;  // 1 % of the reference power at rated speed, no load
};
struct DriftParams {
  bool on = false;
  double coeff_per_K = 0.0;
  double reference_C = kAuto;  // the track's start temperature
};

struct Effects {
  DeadTimeParams deadtime;
  DelayParams delay;
  ThetaOffsetParams theta_offset;
  PhaseErrorParams current_offset{false, {kAuto, 0.0, 0.0}};  // offset_A per phase; a: 0.015·√2·I_n
  PhaseErrorParams current_gain{false, {1.0, 1.03, 1.0}};     // measured/true per phase
  SaturationParams saturation;                                // ld_saturation, lq_saturation, cross_saturation
  HarmonicParams flux_harmonic_6{false, {6, 0.02, 0.4, 0.012, -0.9}};
  HarmonicParams flux_harmonic_12{false, {12, 0.006, 1.1, 0.004, 0.2}};
  IronLossParams iron_loss;
  DriftParams rs_drift{false, 0.00393, kAuto};
  DriftParams psim_drift{false, -0.001, kAuto};
};

/// The effect catalogue: one row per effect name.
struct EffectEntry {
  const char* name;
  bool& (*flag)(Effects&);
  const char* what;
};
const std::vector<EffectEntry>& effect_catalogue();
/// Switches on the named effects (comma-separated; "" or "none": none). Throws std::invalid_argument naming
/// the unknown one and listing the known.
void enable_effects(Effects& e, std::string_view names);
/// The names of the effects that are on, in catalogue order.
std::vector<std::string> enabled_effects(const Effects& e);

struct SensorSettings {
  double current_noise_A = kAuto;  // 0.0035·√2·I_n
  int adc_bits = 12;
  double adc_full_scale_A = kAuto;  // 2.5·√2·I_n
  std::int64_t encoder_counts_per_rev = 1 << 14;
  double u_dc_noise_V = kAuto;  // 0.002·u_dc
  int u_dc_adc_bits = 12;
  double u_dc_full_scale_V = kAuto;  // 1.5·u_dc
  double omega_noise_rad_s = 0.0;
  double temperature_noise_K = 0.0;
};

struct InverterSettings {
  double u_dc_V = kAuto;                  // √2·U_n (the line-to-line rms that space-vector modulation reaches)
  double switching_frequency_Hz = kAuto;  // the control rate
  Modulation modulation = Modulation::space_vector;
};

struct ControlSettings {
  double rate_Hz = 8000.0;
  int substeps = 4;                // RK4 steps per control period
  double bandwidth_Hz = kAuto;     // rate/40
  double current_limit_A = kAuto;  // 1.5·√2·I_n
  double angle_advance_periods = 0.5;
};

struct ProfileSettings {
  std::vector<ProfilePoint> points;  // empty: default_profile
  double max_speed_pu = 0.5;
  double max_torque_pu = 0.8;
};

struct ThermalSettings {
  TemperatureTrack winding;
  TemperatureTrack magnet;
};

enum class AveragedSource { plant, drive };

struct AveragedSettings {
  bool on = false;
  double rate_Hz = 200.0;
  double jitter_rel = 0.3;  // each interval uniformly within (1 ± jitter)/rate
  double min_interval_s = 0.5e-3;
  double max_interval_s = 20e-3;
  AveragedSource source = AveragedSource::plant;
};

struct Case {
  MachineConfig machine;
  std::uint64_t seed = 1;
  double duration_s = 20.0;
  MachineDraw draw;
  Effects effects;
  SensorSettings sensors;
  InverterSettings inverter;
  ControlSettings control;
  ProfileSettings profile;
  ThermalSettings thermal;
  AveragedSettings averaged;
  bool keep_log_rows = true;    // the phase-frame drive log
  bool keep_plant_rows = true;  // the true state per control period
};

/// Fills every kAuto from the machine (README "Defaults") and checks ranges; throws std::invalid_argument.
Case resolve_defaults(Case c);

/// Sets a numeric parameter by its dotted key (README "Parameters"), e.g. "deadtime.t_dead_s".
/// Throws std::invalid_argument for an unknown key or a value out of range.
void set_parameter(Case& c, std::string_view key, double value);
/// Every key set_parameter knows, with its unit and meaning.
struct ParameterEntry {
  const char* key;
  const char* unit;
  void (*set)(Case&, double);
};
const std::vector<ParameterEntry>& parameter_catalogue();

/// Draws the parameters of every enabled effect from the ranges of README "Drawn effect parameters"
/// with the case's seed (a stream of its own: the machine draw does not change).
void draw_effect_parameters(Case& c);

}  // namespace indep
