// The two files the generator writes: VESC Tool's CSV and the truth behind it (README "The CSV", "Truth").
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "indep_vesc/generator.hpp"
#include "indep_vesc/poller.hpp"

namespace indep::vesc {

std::string vesc_tool_csv(const Result& r) {
  const int version = r.resolved.format.header_version;
  const char* eol = r.resolved.format.crlf ? "\r\n" : "\n";
  std::string out;
  out.reserve(r.rows.size() * 420 + 1024);
  if (version > 0) {
    out += header_line(version);
    out += eol;
  }
  for (const LogRow& row : r.rows) {
    out += row_line(version, row.context);
    out += eol;
  }
  return out;
}

std::string cycle_trace_csv(const Result& r) {
  const bool hall = r.resolved.firmware.hall;
  std::string out =
      "t,theta_el,omega_el,phase,frame_error,source,modulating,i_d_true,i_q_true,i_d_reported,i_q_reported,"
      "u_d_reported,u_q_reported,u_d_applied,u_q_applied,psi_m,r_s";
  out += hall ? ",observer_phase,hall_state,hall_weight,hall_interpolating\n" : "\n";
  char buf[512];
  for (const CycleRecord& c : r.cycles) {
    const double eps = std::remainder(c.phase_rad - c.theta_el_rad, 2.0 * kPi);
    std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.4f,%.6f,%.6f,%s,%d,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.7g,%.7g\n",
                  c.t_s, std::remainder(c.theta_el_rad, 2.0 * kPi), c.omega_el_rad_s, c.phase_rad, eps, to_string(c.source),
                  c.modulating ? 1 : 0, c.i_dq_true_A.x, c.i_dq_true_A.y, c.i_dq_reported_A.x, c.i_dq_reported_A.y,
                  c.v_dq_reported_V.x, c.v_dq_reported_V.y, c.v_dq_applied_V.x, c.v_dq_applied_V.y, c.psi_m_Wb, c.r_s_Ohm);
    if (hall) {
      out.append(buf, std::strlen(buf) - 1);  // the line without its end
      std::snprintf(buf, sizeof buf, ",%.6f,%d,%.4f,%d\n", c.observer_phase_rad, c.hall_state, c.hall_weight,
                    c.hall_interpolating ? 1 : 0);
    }
    out += buf;
  }
  return out;
}

namespace {

nlohmann::json machine_json(const MachineValues& m) {
  return {{"psi_m_Wb", m.psi_m_Wb},
          {"r_s_Ohm", m.r_s_Ohm},
          {"l_d_H", m.l_d_H},
          {"l_q_H", m.l_q_H},
          {"pole_pairs", m.pole_pairs}};
}

nlohmann::json row_json(const LogRow& row, int line, bool hall) {
  const RowTruth& t = row.truth;
  nlohmann::json j = {{"line", line},
                      {"ms_today", row.context.ms_today},
                      {"t_s", row.t_reply_s},
                      {"t_read_s", t.t_read_s},
                      {"t_window_start_s", t.t_window_start_s},
                      {"cycles", t.cycles},
                      {"segment", to_string(t.segment)},
                      {"bridge", t.bridge},
                      {"modulating_fraction", t.modulating_fraction},
                      {"angle", t.angle},
                      {"open_loop_fraction", t.open_loop_fraction},
                      {"angle_locked", t.angle_locked},
                      {"frame_error_mean_rad", t.frame_error_mean_rad},
                      {"frame_error_max_abs_rad", t.frame_error_max_abs_rad},
                      {"excites_psi_m", t.excites_psi_m},
                      {"excites_r_s", t.excites_r_s},
                      {"transient", t.transient},
                      {"psi_m_term_V", t.psi_m_term_V},
                      {"r_s_term_V", t.r_s_term_V},
                      {"omega_el_mean_rad_s", t.omega_el_mean_rad_s},
                      {"omega_el_start_rad_s", t.omega_el_start_rad_s},
                      {"omega_el_end_rad_s", t.omega_el_end_rad_s},
                      {"i_d_mean_A", t.i_d_mean_A},
                      {"i_q_mean_A", t.i_q_mean_A},
                      {"i_d_avg_A", t.i_d_avg_A},
                      {"i_q_avg_A", t.i_q_avg_A},
                      {"i_dev_rms_A", t.i_dev_rms_A},
                      {"u_d_mean_V", t.u_d_mean_V},
                      {"u_q_mean_V", t.u_q_mean_V},
                      {"psi_m_Wb", t.psi_m_Wb},
                      {"r_s_Ohm", t.r_s_Ohm},
                      {"T_winding_C", t.T_winding_C},
                      {"T_magnet_C", t.T_magnet_C}};
  if (hall) {
    j["hall_fraction"] = t.hall_fraction;
    j["hall_weight_mean"] = t.hall_weight_mean;
    j["hall_interpolated_fraction"] = t.hall_interpolated_fraction;
  }
  return j;
}

}  // namespace

std::string truth_json(const Result& r) {
  const Case& c = r.resolved;
  nlohmann::json j;
  j["generator"] = "indep_vesc_log (tests/independent_vesc)";
  j["config"] = c.machine.source;
  j["seed"] = c.seed;
  j["duration_s"] = c.duration_s;
  j["header_version"] = c.format.header_version;
  j["columns"] = column_count(c.format.header_version);
  j["start_ms_today"] = c.format.start_ms_today;
  j["clock"] = clock_is_utc(c.format.header_version) ? "UTC" : "local";
  j["configured_machine"] = machine_json(r.configured);
  j["true_machine"] = machine_json(r.true_at_reference);
  j["true_machine"]["reference_temperature_C"] = c.thermal.reference_C;
  j["true_over_configured"] = {{"psi_m", r.true_at_reference.psi_m_Wb / r.configured.psi_m_Wb},
                               {"r_s", r.true_at_reference.r_s_Ohm / r.configured.r_s_Ohm}};
  j["true_at_end"] = {{"psi_m_Wb", r.end_psi_m_Wb},
                      {"r_s_Ohm", r.end_r_s_Ohm},
                      {"T_winding_C", r.end_T_winding_C},
                      {"T_magnet_C", r.end_T_magnet_C}};
  j["thermal"] = {
      {"on", c.thermal.on},
      {"ambient_C", c.thermal.ambient_C},
      {"winding_start_C", c.thermal.winding_start_C},
      {"magnet_start_C", c.thermal.magnet_start_C},
      {"r_s_coeff_per_K", c.thermal.r_s_coeff_per_K},
      {"psi_m_coeff_per_K", c.thermal.psi_m_coeff_per_K},
      {"winding_tau_s", c.thermal.winding_tau_s},
      {"magnet_tau_s", c.thermal.magnet_tau_s},
      {"law", "r_s = r_s_ref*(1 + r_s_coeff*(T_winding - ref)); psi_m = psi_m_ref*(1 + psi_m_coeff*(T_magnet - ref))"}};
  j["vesc"] = {{"configuration_at_start", machine_json(r.vesc_configuration)},
               {"measured_flux_linkage_Wb",
                r.vesc_measured_flux_Wb ? nlohmann::json(*r.vesc_measured_flux_Wb) : nlohmann::json(nullptr)},
               {"control_period_s", r.control_period_s},
               {"f_zv_Hz", c.firmware.f_zv_Hz},
               {"foc_dt_us", c.firmware.foc_dt_us},
               {"current_kp", r.firmware.kp},
               {"current_ki", r.firmware.ki},
               {"l_current_max_A", c.firmware.l_current_max_A},
               {"openloop_erpm", c.firmware.openloop_erpm},
               {"vdq_filter", c.firmware.vdq_filter},
               {"off_voltage", c.firmware.off_voltage == OffVoltage::measured ? "measured" : "zero"},
               {"invert_direction", c.firmware.invert_direction}};
  j["power_stage"] = {{"v_oc_V", c.power.v_oc_V},
                      {"r_internal_Ohm", c.power.r_internal_Ohm},
                      {"t_dead_s", c.power.t_dead_s},
                      {"f_sw_Hz", r.plant.f_sw_Hz},
                      {"dead_band_A", c.power.dead_band_A}};
  j["sensors"] = {{"current_lsb_A", c.sensors.current_lsb_A},
                  {"current_noise_lsb", c.sensors.current_noise_lsb},
                  {"voltage_lsb_V", c.sensors.voltage_lsb_V},
                  {"bus_gain", c.sensors.bus_gain},
                  {"phase_voltage_gain", c.sensors.phase_voltage_gain}};
  j["mechanics"] = {{"inertia_kgm2", c.mechanics.inertia_kgm2},
                    {"coulomb_Nm", c.mechanics.coulomb_Nm},
                    {"viscous_Nm_s", c.mechanics.viscous_Nm_s},
                    {"drag_Nm_s2", c.mechanics.drag_Nm_s2},
                    {"external_Nm", c.mechanics.external_Nm}};
  if (c.firmware.hall) {  // only in Hall mode: the sensorless file stays as it was
    j["vesc"]["foc_sensor_mode"] = "hall";
    nlohmann::json table = nlohmann::json::array();
    for (const int v : r.firmware.hall_table) table.push_back(v);
    j["vesc"]["foc_hall_table"] = table;
    j["vesc"]["foc_hall_interp_erpm"] = c.firmware.hall_interp_erpm;
    j["vesc"]["foc_sl_erpm_start"] = c.firmware.sl_erpm_start;
    j["vesc"]["foc_sl_erpm"] = c.firmware.sl_erpm;
    j["sensors"]["hall_offset_deg"] = c.sensors.hall_offset_deg;
  }
  j["reads"] = {{"poll_rate_Hz", c.poller.poll_rate_Hz},
                {"rate_Hz", c.poller.rate_Hz},
                {"rtt_median_s", rtt_median_s(c.poller)},
                {"loss_probability", c.poller.loss_probability},
                {"reads", r.reads},
                {"lost_replies", r.lost_replies},
                {"rows", r.rows.size()}};
  j["rules"] = {{"locked_max_frame_error_rad", c.rules.locked_max_frame_error_rad},
                {"excites_psi_m_min_V", c.rules.excites_psi_m_min_V},
                {"excites_r_s_min_V", c.rules.excites_r_s_min_V},
                {"transient_speed_rel", c.rules.transient_speed_rel},
                {"transient_speed_floor_rad_s", c.rules.transient_speed_floor_rad_s},
                {"transient_current_rms_A", c.rules.transient_current_rms_A}};
  nlohmann::json spans = nlohmann::json::array();
  for (const SegmentSpan& s : r.spans) {
    spans.push_back({{"kind", to_string(s.segment.kind)},
                     {"t_start_s", s.t_start_s},
                     {"t_end_s", s.t_end_s},
                     {"current_A", s.segment.current_A}});
  }
  j["scenario"] = spans;

  std::map<std::string, int> counts;
  nlohmann::json rows = nlohmann::json::array();
  const int first_line = c.format.header_version > 0 ? 2 : 1;
  for (std::size_t k = 0; k < r.rows.size(); ++k) {
    const RowTruth& t = r.rows[k].truth;
    ++counts["bridge." + t.bridge];
    ++counts["angle." + t.angle];
    counts["angle_locked"] += t.angle_locked ? 1 : 0;
    counts["excites_psi_m"] += t.excites_psi_m ? 1 : 0;
    counts["excites_r_s"] += t.excites_r_s ? 1 : 0;
    counts["transient"] += t.transient ? 1 : 0;
    ++counts[std::string("segment.") + to_string(t.segment)];
    rows.push_back(row_json(r.rows[k], first_line + static_cast<int>(k), c.firmware.hall));
  }
  j["counts"] = counts;
  j["rows"] = rows;
  return j.dump();
}

}  // namespace indep::vesc
