#pragma once
// A case of the independent VESC Tool log generator: every setting in SI, grouped by the part it belongs to
// (README "Parameters"). Fields set to kAuto take the default README gives, derived from the configured
// machine; resolve_defaults() fills them in and checks ranges.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "indep_drive/machine_config.hpp"
#include "indep_vesc/scenario.hpp"

namespace indep::vesc {

inline constexpr double kAuto = std::numeric_limits<double>::quiet_NaN();

/// The true machine against the configured one: each of ψm and R_s off by a fixed relative offset, or by one
/// drawn from the seed with a magnitude uniform in [span_min, span_max] and a random sign.
struct MachineDraw {
  std::optional<double> psi_m_rel, r_s_rel;  // true/configured − 1 at the reference temperature
  double span_min = 0.10, span_max = 0.30;
  double l_rel = 0.0;  // L_d and L_q, true/configured − 1
};

/// The shaft: J·dω_m/dt = T_e − T_c·σ(ω_m/ω_ε) − b·ω_m − k·ω_m·|ω_m| − T_ext (an outrunner on a bench driving
/// a propeller-like load: bearings and a quadratic drag; README "Mechanics").
struct Mechanics {
  double inertia_kgm2 = kAuto;      // τ_m·T_n/ω_n,mech with τ_m = 0.12 s
  double coulomb_Nm = kAuto;        // 0.3 % of T_n
  double coulomb_band_rad_s = 0.5;  // ω_ε
  double viscous_Nm_s = 0.0;
  double drag_Nm_s2 = kAuto;  // 15 % of T_n at rated speed
  double external_Nm = 0.0;   // a constant load torque (tests)
};

/// Winding and magnet temperatures (first-order, README "Thermal") and the laws of R_s and ψm.
struct Thermal {
  bool on = true;
  double ambient_C = 25.0;
  double winding_start_C = kAuto;         // ambient
  double magnet_start_C = kAuto;          // ambient
  double reference_C = 25.0;              // where the true machine's ψm and R_s are stated
  double winding_rise_at_rated_K = 80.0;  // steady winding rise at rated current: sets R_th
  double winding_tau_s = 300.0;
  double magnet_tau_s = 900.0;
  double magnet_coupling = 0.7;        // steady magnet rise / winding rise
  double r_s_coeff_per_K = 0.00393;    // copper
  double psi_m_coeff_per_K = -0.0011;  // NdFeB
};

/// Battery and power stage (README "Inverter").
struct PowerStage {
  double v_oc_V = kAuto;          // √2·U_n
  double r_internal_Ohm = kAuto;  // 5 % sag at the reference power
  double t_dead_s = kAuto;        // the dead time the firmware's compensation assumes: (4/3)·foc_dt_us
  double dead_band_A = 0.5;       // width of the dead-time error's sign change around zero current
};

/// The VESC's current, bus-voltage and phase-voltage measurement (README "Sensors"; VESC 6 defaults).
struct Sensors {
  double current_lsb_A = kAuto;              // V_REG/4095/(R_shunt·gain) = 3.3/4095/(0.0005·20) for a VESC 6
  double current_noise_lsb = 1.0;            // Gaussian, per phase and sample, in ADC counts
  double current_offset_residual_lsb = 0.3;  // σ of the offset left after the VESC's calibration, per phase
  double voltage_lsb_V = kAuto;              // V_REG/4095·(R1+R2)/R2 = 3.3/4095·41200/2200
  double voltage_noise_lsb = 1.0;
  double bus_gain = 1.0;            // measured/true input voltage (the divider's tolerance)
  double phase_voltage_gain = 1.0;  // measured/true phase voltage (undriven back-EMF tracking)
  double motor_temp_noise_K = 0.3;
  double motor_sensor_fitted = 1.0;  // 0: no motor NTC, its ADC input open (README "What runs", the columns)
  double fet_temp_start_C = kAuto;   // ambient
  double hall_offset_deg = 0.0;      // Hall mode: sensor 1's electrical position from phase a (hall.hpp)
};

enum class OffVoltage { measured, zero };

/// The VESC's motor configuration and what its firmware does with it (README "Firmware").
struct Firmware {
  double f_zv_Hz = 25000.0;       // foc_f_zv; control and sampling at f_zv/2 (V0 sampling)
  double foc_dt_us = 0.12;        // dead-time compensation
  double current_tc_s = 1000e-6;  // detection's current-controller time constant: kp = L/tc, ki = R/tc
  double detect_r_rel = 0.05;     // VESC's detected R/true − 1
  double detect_l_rel = 0.10;
  double detect_psi_rel = -0.03;        // replaced by the emulated flux measurement when the scenario runs one
  double observer_gain_factor = 0.5e3;  // foc_observer_gain = factor/ψ²
  double observer_gain_slow = 0.05;
  double observer_offset = -1.0;  // foc_observer_offset, control periods
  double pll_kp = 2000.0, pll_ki = 30000.0;
  double openloop_erpm = 1500.0, openloop_erpm_low = 0.0;
  double sl_openloop_hyst_s = 0.1, sl_openloop_time_lock_s = 0.0, sl_openloop_time_ramp_s = 0.1, sl_openloop_time_s = 0.05;
  double sl_openloop_boost_q_A = 0.0, sl_openloop_max_q_A = -1.0;
  double l_current_max_A = kAuto;  // 1.5·√2·I_n
  double cc_min_current_A = 0.05;
  double l_max_duty = 0.95;
  double mag_vd_max = 0.98;
  double overmod_factor = 1.0;
  double current_filter_const = 0.1;
  bool vdq_filter = true;  // firmware ≥ 5.03: reported v_dq through the speed-dependent low pass
  OffVoltage off_voltage = OffVoltage::measured;
  bool invert_direction = false;  // m_invert_direction: iq, vq, erpm, duty, tachometer negated
  int controller_id = 0;
  // Hall mode (foc_sensor_mode = FOC_SENSOR_MODE_HALL; README "Hall mode"); the table is what the emulated
  // detection finds for the sensors (hall.hpp).
  bool hall = false;
  double hall_interp_erpm = 500.0;  // foc_hall_interp_erpm
  double sl_erpm_start = 2500.0;    // foc_sl_erpm_start
  double sl_erpm = 3500.0;          // foc_sl_erpm
};

/// VESC Tool's polling of COMM_GET_VALUES and the link's timing (README "Reads").
struct Poller {
  double rate_Hz = 11.0;        // mean row rate the link allows (8–15 Hz in the field)
  double poll_rate_Hz = 50.0;   // VESC Tool's "poll_rate_rt_data" (its timer: int(1000/rate) ms)
  double rtt_sigma_log = 0.25;  // log-normal spread of the round trip
  double rtt_min_s = 0.04;
  double loss_probability = 0.004;   // a request or a reply lost: the next after VESC Tool's 1 s time-out
  double stall_probability = 0.003;  // a link stall that delays one reply by U[0.3, stall_max_s]
  double stall_max_s = 1.5;
  double setup_reply_delay_s = 0.003;  // COMM_GET_VALUES_SETUP's reply after the values' reply
};

/// The file VESC Tool writes (README "The CSV").
struct LogFormat {
  int header_version = 3;         // 0 (no header, 22 columns), 1 (22), 2 (32), 3 (55, newest)
  double start_ms_today = kAuto;  // logger clock at t = 0 [ms since midnight]; drawn in [08:00, 20:00)
  bool midnight = false;          // start so that midnight falls at a third of the log
  bool crlf = false;              // Windows line ends (QIODevice::Text)
};

/// Wheel and battery settings behind the setup columns (VESC defaults, mcconf_default.h).
struct SetupSettings {
  double wheel_diameter_m = 0.083;
  double gear_ratio = 3.0;
  double battery_ah = 6.0;
};

/// Thresholds of the per-row regime truth (README "Truth").
struct TruthRules {
  double locked_max_frame_error_rad = 0.1;
  double excites_psi_m_min_V = 0.05;  // |ω̄·ψm|
  double excites_r_s_min_V = 0.02;    // R_s·|ī|
  double transient_speed_rel = 0.05;  // |Δω_el| > rel·max(|ω̄_el|, transient_speed_floor)
  double transient_speed_floor_rad_s = 100.0;
  double transient_current_rms_A = 1.0;  // rms of |i| about its window mean
};

struct Case {
  MachineConfig machine;  // the configuration the estimator is told
  std::uint64_t seed = 1;
  double duration_s = 600.0;
  MachineDraw draw;
  Mechanics mechanics;
  Thermal thermal;
  PowerStage power;
  Sensors sensors;
  Firmware firmware;
  Poller poller;
  LogFormat format;
  SetupSettings setup;
  TruthRules rules;
  std::vector<Segment> scenario;  // empty: the built-in one drawn from the seed (scenario.hpp)
  bool keep_cycle_trace = false;  // per control cycle record (tests, --trace)
  int trace_every = 1;            // keep every n-th cycle
};

/// Fills every kAuto and checks ranges; throws std::invalid_argument naming the field.
Case resolve_defaults(Case c);

/// Sets a numeric parameter by its dotted key, e.g. "firmware.foc_dt_us" (README "Parameters").
/// Throws std::invalid_argument for an unknown key or a value out of range.
void set_parameter(Case& c, std::string_view key, double value);

struct ParameterEntry {
  const char* key;
  const char* unit;
  double& (*field)(Case&);
};
/// The one table of numeric parameters.
const std::vector<ParameterEntry>& parameter_catalogue();

}  // namespace indep::vesc
