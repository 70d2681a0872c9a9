#include "indep_vesc/case.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "indep_drive/frames.hpp"
#include "indep_vesc/random_streams.hpp"

namespace indep::vesc {

namespace {

void fill(double& v, double value) {
  if (std::isnan(v)) v = value;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

void in_range(double v, double lo, double hi, const char* key) {
  require(std::isfinite(v) && v >= lo && v <= hi, std::string(key) + " = " + std::to_string(v) + " is outside [" +
                                                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

// The VESC 6's measurement chain (vedderb/bldc hwconf/trampa/vesc6/hw_60_core.h): 12-bit ADC at V_REG 3.3 V,
// 0.5 mΩ shunts with a gain of 20, an input divider of 39 kΩ over 2.2 kΩ.
constexpr double kVReg = 3.3, kShunt = 0.0005, kAmpGain = 20.0, kVinR1 = 39000.0, kVinR2 = 2200.0;

}  // namespace

Case resolve_defaults(Case c) {
  const MachineConfig& m = c.machine;
  require(m.params.pole_pairs > 0 && m.params.psi_m_Wb > 0.0 && m.params.r_s_Ohm > 0.0 && m.params.l_d_H > 0.0 &&
              m.params.l_q_H > 0.0 && m.rated.current_rms_A > 0.0 && m.rated.speed_rpm > 0.0 &&
              m.rated.voltage_ll_rms_V > 0.0,
          "machine: pole pairs, psi_m, r_s, l_d, l_q and the rated current, speed and voltage must be positive");
  in_range(c.duration_s, 1e-3, 86400.0, "duration_s");
  in_range(c.draw.span_min, 0.0, 0.9, "draw.span_min");
  in_range(c.draw.span_max, c.draw.span_min, 0.9, "draw.span_max");
  in_range(c.draw.l_rel, -0.5, 1.0, "draw.l_rel");
  if (c.draw.psi_m_rel) in_range(*c.draw.psi_m_rel, -0.9, 2.0, "psi_m_rel");
  if (c.draw.r_s_rel) in_range(*c.draw.r_s_rel, -0.9, 2.0, "r_s_rel");

  const double t_n = m.torque_base_Nm();
  const double w_n = 2.0 * kPi * m.rated.speed_rpm / 60.0;  // mechanical
  Mechanics& k = c.mechanics;
  fill(k.inertia_kgm2, 0.12 * t_n / w_n);
  fill(k.coulomb_Nm, 0.003 * t_n);
  fill(k.drag_Nm_s2, 0.15 * t_n / (w_n * w_n));
  in_range(k.inertia_kgm2, 1e-9, 1e6, "mech.inertia_kgm2");
  in_range(k.coulomb_Nm, 0.0, 1e6, "mech.coulomb_Nm");
  in_range(k.coulomb_band_rad_s, 1e-6, 1e3, "mech.coulomb_band_rad_s");
  in_range(k.viscous_Nm_s, 0.0, 1e6, "mech.viscous_Nm_s");
  in_range(k.drag_Nm_s2, 0.0, 1e6, "mech.drag_Nm_s2");
  in_range(k.external_Nm, -1e6, 1e6, "mech.external_Nm");

  Thermal& th = c.thermal;
  fill(th.winding_start_C, th.ambient_C);
  fill(th.magnet_start_C, th.ambient_C);
  in_range(th.ambient_C, -50.0, 150.0, "thermal.ambient_C");
  in_range(th.winding_start_C, -50.0, 250.0, "thermal.winding_start_C");
  in_range(th.magnet_start_C, -50.0, 250.0, "thermal.magnet_start_C");
  in_range(th.winding_rise_at_rated_K, 1.0, 300.0, "thermal.winding_rise_at_rated_K");
  in_range(th.winding_tau_s, 1.0, 1e6, "thermal.winding_tau_s");
  in_range(th.magnet_tau_s, 1.0, 1e6, "thermal.magnet_tau_s");
  in_range(th.magnet_coupling, 0.0, 1.0, "thermal.magnet_coupling");

  PowerStage& pw = c.power;
  fill(pw.v_oc_V, std::sqrt(2.0) * m.rated.voltage_ll_rms_V);
  fill(pw.r_internal_Ohm, 0.05 * pw.v_oc_V * pw.v_oc_V / m.reference_power_W());
  // The firmware's compensation (update_valpha_vbeta) takes foc_dt_us·f_zv of modulation per sign, i.e. a leg
  // error of (2/3)·foc_dt_us·f_zv·V_bus = (4/3)·foc_dt_us·f_sw·V_bus; a dead time t_d loses t_d·f_sw·V_bus per leg.
  fill(pw.t_dead_s, 4.0 / 3.0 * c.firmware.foc_dt_us * 1e-6);
  in_range(pw.v_oc_V, 1.0, 2000.0, "power.v_oc_V");
  in_range(pw.r_internal_Ohm, 0.0, 100.0, "power.r_internal_Ohm");
  in_range(pw.t_dead_s, 0.0, 10e-6, "power.t_dead_s");
  in_range(pw.dead_band_A, 1e-6, 1e3, "power.dead_band_A");

  Sensors& s = c.sensors;
  fill(s.current_lsb_A, kVReg / 4095.0 / (kShunt * kAmpGain));
  fill(s.voltage_lsb_V, kVReg / 4095.0 * (kVinR1 + kVinR2) / kVinR2);
  fill(s.fet_temp_start_C, th.ambient_C);
  in_range(s.current_lsb_A, 1e-6, 100.0, "sensors.current_lsb_A");
  in_range(s.voltage_lsb_V, 1e-6, 10.0, "sensors.voltage_lsb_V");
  in_range(s.current_noise_lsb, 0.0, 100.0, "sensors.current_noise_lsb");
  in_range(s.voltage_noise_lsb, 0.0, 100.0, "sensors.voltage_noise_lsb");
  in_range(s.bus_gain, 0.5, 1.5, "sensors.bus_gain");
  in_range(s.phase_voltage_gain, 0.5, 1.5, "sensors.phase_voltage_gain");
  require(s.motor_sensor_fitted == 0.0 || s.motor_sensor_fitted == 1.0,
          "sensors.motor_sensor_fitted is 1 (fitted) or 0 (none)");
  require(4095.0 * s.current_lsb_A / 2.0 > 1.5 * std::sqrt(2.0) * m.rated.current_rms_A * 1.5,
          "sensors.current_lsb_A: the ADC's range (±2048 counts) does not cover the current limit");

  Firmware& f = c.firmware;
  fill(f.l_current_max_A, 1.5 * std::sqrt(2.0) * m.rated.current_rms_A);
  in_range(f.f_zv_Hz, 2000.0, 100000.0, "firmware.f_zv_Hz");
  in_range(f.foc_dt_us, 0.0, 5.0, "firmware.foc_dt_us");
  in_range(f.current_tc_s, 1e-5, 1e-1, "firmware.current_tc_s");
  in_range(f.detect_r_rel, -0.5, 1.0, "firmware.detect_r_rel");
  in_range(f.detect_l_rel, -0.5, 1.0, "firmware.detect_l_rel");
  in_range(f.detect_psi_rel, -0.5, 1.0, "firmware.detect_psi_rel");
  in_range(f.l_current_max_A, 0.1, 1e5, "firmware.l_current_max_A");
  in_range(f.cc_min_current_A, 0.0, 10.0, "firmware.cc_min_current_A");
  in_range(f.l_max_duty, 0.1, 0.99, "firmware.l_max_duty");
  in_range(f.openloop_erpm, 0.0, 1e5, "firmware.openloop_erpm");
  in_range(f.sl_openloop_hyst_s, 0.001, 10.0, "firmware.sl_openloop_hyst_s");
  in_range(f.hall_interp_erpm, 0.0, 1e5, "firmware.hall_interp_erpm");
  in_range(f.sl_erpm_start, 0.0, 1e5, "firmware.sl_erpm_start");
  in_range(f.sl_erpm, f.sl_erpm_start + 1.0, 2e5, "firmware.sl_erpm (above firmware.sl_erpm_start)");
  in_range(s.hall_offset_deg, -360.0, 360.0, "sensors.hall_offset_deg");

  Poller& p = c.poller;
  in_range(p.poll_rate_Hz, 1.0, 1000.0, "poller.poll_rate_Hz");
  in_range(p.rate_Hz, 0.1, 1000.0 / std::floor(1000.0 / p.poll_rate_Hz), "poller.rate_Hz (at most the poll rate)");
  in_range(p.rtt_sigma_log, 0.0, 2.0, "poller.rtt_sigma_log");
  in_range(p.rtt_min_s, 0.0, 1.0, "poller.rtt_min_s");
  in_range(p.loss_probability, 0.0, 0.5, "poller.loss_probability");
  in_range(p.stall_probability, 0.0, 0.5, "poller.stall_probability");
  in_range(p.stall_max_s, 0.3, 10.0, "poller.stall_max_s");

  require(c.trace_every >= 1, "trace_every must be at least 1");

  LogFormat& fmt = c.format;
  require(fmt.header_version >= 0 && fmt.header_version <= 3, "format.header_version must be 0, 1, 2 or 3");
  if (std::isnan(fmt.start_ms_today)) {
    if (fmt.midnight) {
      fmt.start_ms_today = 86'400'000.0 - c.duration_s / 3.0 * 1000.0;
    } else {
      std::mt19937_64 rng = stream_rng(c.seed, Stream::clock);
      fmt.start_ms_today = std::floor(std::uniform_real_distribution<double>(8.0, 20.0)(rng) * 3'600'000.0);
    }
  }
  in_range(fmt.start_ms_today, 0.0, 86'400'000.0 - 1e-3, "format.start_ms_today");
  return c;
}

#define INDEP_VESC_PARAM(key, unit, member)                \
  {                                                        \
    key, unit, [](Case& c) -> double& { return c.member; } \
  }

const std::vector<ParameterEntry>& parameter_catalogue() {
  static const std::vector<ParameterEntry> table = {
      INDEP_VESC_PARAM("draw.span_min", "1", draw.span_min),
      INDEP_VESC_PARAM("draw.span_max", "1", draw.span_max),
      INDEP_VESC_PARAM("draw.l_rel", "1", draw.l_rel),
      INDEP_VESC_PARAM("mech.inertia_kgm2", "kg m^2", mechanics.inertia_kgm2),
      INDEP_VESC_PARAM("mech.coulomb_Nm", "Nm", mechanics.coulomb_Nm),
      INDEP_VESC_PARAM("mech.coulomb_band_rad_s", "rad/s", mechanics.coulomb_band_rad_s),
      INDEP_VESC_PARAM("mech.viscous_Nm_s", "Nm s", mechanics.viscous_Nm_s),
      INDEP_VESC_PARAM("mech.drag_Nm_s2", "Nm s^2", mechanics.drag_Nm_s2),
      INDEP_VESC_PARAM("mech.external_Nm", "Nm", mechanics.external_Nm),
      INDEP_VESC_PARAM("thermal.ambient_C", "degC", thermal.ambient_C),
      INDEP_VESC_PARAM("thermal.winding_start_C", "degC", thermal.winding_start_C),
      INDEP_VESC_PARAM("thermal.magnet_start_C", "degC", thermal.magnet_start_C),
      INDEP_VESC_PARAM("thermal.reference_C", "degC", thermal.reference_C),
      INDEP_VESC_PARAM("thermal.winding_rise_at_rated_K", "K", thermal.winding_rise_at_rated_K),
      INDEP_VESC_PARAM("thermal.winding_tau_s", "s", thermal.winding_tau_s),
      INDEP_VESC_PARAM("thermal.magnet_tau_s", "s", thermal.magnet_tau_s),
      INDEP_VESC_PARAM("thermal.magnet_coupling", "1", thermal.magnet_coupling),
      INDEP_VESC_PARAM("thermal.r_s_coeff_per_K", "1/K", thermal.r_s_coeff_per_K),
      INDEP_VESC_PARAM("thermal.psi_m_coeff_per_K", "1/K", thermal.psi_m_coeff_per_K),
      INDEP_VESC_PARAM("power.v_oc_V", "V", power.v_oc_V),
      INDEP_VESC_PARAM("power.r_internal_Ohm", "Ohm", power.r_internal_Ohm),
      INDEP_VESC_PARAM("power.t_dead_s", "s", power.t_dead_s),
      INDEP_VESC_PARAM("power.dead_band_A", "A", power.dead_band_A),
      INDEP_VESC_PARAM("sensors.current_lsb_A", "A", sensors.current_lsb_A),
      INDEP_VESC_PARAM("sensors.current_noise_lsb", "counts", sensors.current_noise_lsb),
      INDEP_VESC_PARAM("sensors.current_offset_residual_lsb", "counts", sensors.current_offset_residual_lsb),
      INDEP_VESC_PARAM("sensors.voltage_lsb_V", "V", sensors.voltage_lsb_V),
      INDEP_VESC_PARAM("sensors.voltage_noise_lsb", "counts", sensors.voltage_noise_lsb),
      INDEP_VESC_PARAM("sensors.bus_gain", "1", sensors.bus_gain),
      INDEP_VESC_PARAM("sensors.phase_voltage_gain", "1", sensors.phase_voltage_gain),
      INDEP_VESC_PARAM("sensors.motor_temp_noise_K", "K", sensors.motor_temp_noise_K),
      INDEP_VESC_PARAM("sensors.motor_sensor_fitted", "1", sensors.motor_sensor_fitted),
      INDEP_VESC_PARAM("sensors.fet_temp_start_C", "degC", sensors.fet_temp_start_C),
      INDEP_VESC_PARAM("sensors.hall_offset_deg", "deg", sensors.hall_offset_deg),
      INDEP_VESC_PARAM("firmware.f_zv_Hz", "Hz", firmware.f_zv_Hz),
      INDEP_VESC_PARAM("firmware.foc_dt_us", "us", firmware.foc_dt_us),
      INDEP_VESC_PARAM("firmware.current_tc_s", "s", firmware.current_tc_s),
      INDEP_VESC_PARAM("firmware.detect_r_rel", "1", firmware.detect_r_rel),
      INDEP_VESC_PARAM("firmware.detect_l_rel", "1", firmware.detect_l_rel),
      INDEP_VESC_PARAM("firmware.detect_psi_rel", "1", firmware.detect_psi_rel),
      INDEP_VESC_PARAM("firmware.observer_gain_factor", "1/s", firmware.observer_gain_factor),
      INDEP_VESC_PARAM("firmware.observer_gain_slow", "1", firmware.observer_gain_slow),
      INDEP_VESC_PARAM("firmware.observer_offset", "periods", firmware.observer_offset),
      INDEP_VESC_PARAM("firmware.pll_kp", "1/s", firmware.pll_kp),
      INDEP_VESC_PARAM("firmware.pll_ki", "1/s^2", firmware.pll_ki),
      INDEP_VESC_PARAM("firmware.openloop_erpm", "ERPM", firmware.openloop_erpm),
      INDEP_VESC_PARAM("firmware.openloop_erpm_low", "1", firmware.openloop_erpm_low),
      INDEP_VESC_PARAM("firmware.sl_openloop_hyst_s", "s", firmware.sl_openloop_hyst_s),
      INDEP_VESC_PARAM("firmware.sl_openloop_time_lock_s", "s", firmware.sl_openloop_time_lock_s),
      INDEP_VESC_PARAM("firmware.sl_openloop_time_ramp_s", "s", firmware.sl_openloop_time_ramp_s),
      INDEP_VESC_PARAM("firmware.sl_openloop_time_s", "s", firmware.sl_openloop_time_s),
      INDEP_VESC_PARAM("firmware.sl_openloop_boost_q_A", "A", firmware.sl_openloop_boost_q_A),
      INDEP_VESC_PARAM("firmware.sl_openloop_max_q_A", "A", firmware.sl_openloop_max_q_A),
      INDEP_VESC_PARAM("firmware.l_current_max_A", "A", firmware.l_current_max_A),
      INDEP_VESC_PARAM("firmware.cc_min_current_A", "A", firmware.cc_min_current_A),
      INDEP_VESC_PARAM("firmware.l_max_duty", "1", firmware.l_max_duty),
      INDEP_VESC_PARAM("firmware.mag_vd_max", "1", firmware.mag_vd_max),
      INDEP_VESC_PARAM("firmware.overmod_factor", "1", firmware.overmod_factor),
      INDEP_VESC_PARAM("firmware.current_filter_const", "1", firmware.current_filter_const),
      INDEP_VESC_PARAM("firmware.hall_interp_erpm", "ERPM", firmware.hall_interp_erpm),
      INDEP_VESC_PARAM("firmware.sl_erpm_start", "ERPM", firmware.sl_erpm_start),
      INDEP_VESC_PARAM("firmware.sl_erpm", "ERPM", firmware.sl_erpm),
      INDEP_VESC_PARAM("poller.rate_Hz", "Hz", poller.rate_Hz),
      INDEP_VESC_PARAM("poller.poll_rate_Hz", "Hz", poller.poll_rate_Hz),
      INDEP_VESC_PARAM("poller.rtt_sigma_log", "1", poller.rtt_sigma_log),
      INDEP_VESC_PARAM("poller.rtt_min_s", "s", poller.rtt_min_s),
      INDEP_VESC_PARAM("poller.loss_probability", "1", poller.loss_probability),
      INDEP_VESC_PARAM("poller.stall_probability", "1", poller.stall_probability),
      INDEP_VESC_PARAM("poller.stall_max_s", "s", poller.stall_max_s),
      INDEP_VESC_PARAM("poller.setup_reply_delay_s", "s", poller.setup_reply_delay_s),
      INDEP_VESC_PARAM("format.start_ms_today", "ms", format.start_ms_today),
      INDEP_VESC_PARAM("setup.wheel_diameter_m", "m", setup.wheel_diameter_m),
      INDEP_VESC_PARAM("setup.gear_ratio", "1", setup.gear_ratio),
      INDEP_VESC_PARAM("setup.battery_ah", "Ah", setup.battery_ah),
      INDEP_VESC_PARAM("rules.locked_max_frame_error_rad", "rad", rules.locked_max_frame_error_rad),
      INDEP_VESC_PARAM("rules.excites_psi_m_min_V", "V", rules.excites_psi_m_min_V),
      INDEP_VESC_PARAM("rules.excites_r_s_min_V", "V", rules.excites_r_s_min_V),
      INDEP_VESC_PARAM("rules.transient_speed_rel", "1", rules.transient_speed_rel),
      INDEP_VESC_PARAM("rules.transient_speed_floor_rad_s", "rad/s", rules.transient_speed_floor_rad_s),
      INDEP_VESC_PARAM("rules.transient_current_rms_A", "A", rules.transient_current_rms_A),
  };
  return table;
}

#undef INDEP_VESC_PARAM

void set_parameter(Case& c, std::string_view key, double value) {
  for (const ParameterEntry& e : parameter_catalogue()) {
    if (key == e.key) {
      require(std::isfinite(value), std::string(key) + ": not a finite number");
      e.field(c) = value;
      return;
    }
  }
  throw std::invalid_argument("unknown parameter '" + std::string(key) + "' (--list-parameters)");
}

}  // namespace indep::vesc
