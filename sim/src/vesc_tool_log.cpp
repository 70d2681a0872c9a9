#include "rpem/sim/vesc_tool_log.hpp"

#include <algorithm>
#include <cstdio>

#include "rpem/io/errors.hpp"

namespace rpem::sim {
namespace {

/// printf's %.6g (fixed8 false) or %.8f; a negative zero is written as zero (QLocaleData::doubleToString
/// marks a number negative only if it is not zero).
void append_printf(std::string& out, bool fixed8, double v) {
  if (v == 0.0) v = 0.0;  // drops the sign of −0
  char buf[400];          // %.8f of the largest double: 309 digits and 9 more
  const int n = fixed8 ? std::snprintf(buf, sizeof buf, "%.8f", v) : std::snprintf(buf, sizeof buf, "%.6g", v);
  if (n > 0) out.append(buf, std::min(static_cast<std::size_t>(n), sizeof buf - 1));
}

void append_int(std::string& out, long long v) { out += std::to_string(v); }

}  // namespace

void append_qt_double(std::string& out, double v) {
  // SmartNotation is QLocaleData::DFSignificantDigits: with P = 6 significant digits, fixed if the decimal
  // exponent X satisfies −4 ≤ X < P, else exponent form; trailing zeros chopped; the exponent signed and
  // of at least two digits (QLocale's default ZeroPadExponent) — C's %.6g.
  append_printf(out, false, v);
}

void append_qt_fixed8(std::string& out, double v) { append_printf(out, true, v); }

std::string vesc_tool_header() {
  std::string h;
  for (const char* name : kVescToolColumns) (h += name) += ';';
  h += '\n';
  return h;
}

void append_vesc_tool_row(std::string& out, const VescToolRow& r) {
  const can::vesc::Values& v = r.values;
  auto number = [&out](double x) {
    append_qt_double(out, x);
    out += ';';
  };
  auto integer = [&out](long long x) {
    append_int(out, x);
    out += ';';
  };
  auto fixed = [&out](double x) {
    append_qt_fixed8(out, x);
    out += ';';
  };

  integer(r.ms_today);
  number(v.v_in_V);
  number(v.temp_fet_C);  // MC_VALUES temp_mos: the reply's FET temperature (mc_interface_temp_fet_filtered)
  for (double t : v.temp_mos_C) number(t);
  number(v.temp_motor_C);
  number(v.current_motor_A);
  number(v.current_in_A);
  number(v.i_d_A);
  number(v.i_q_A);
  number(v.erpm);
  number(v.duty);
  number(v.amp_hours_Ah);
  number(v.amp_hours_charged_Ah);
  number(v.watt_hours_Wh);
  number(v.watt_hours_charged_Wh);
  integer(v.tachometer);
  integer(v.tachometer_abs);
  number(v.pid_pos_deg);  // MC_VALUES position
  integer(v.fault);       // mc_fault_code, an enum: written as its integer
  integer(v.controller_id);
  number(v.v_d_V);
  number(v.v_q_V);

  const VescSetupValues& s = r.setup;
  integer(r.ms_today_setup);
  number(s.amp_hours_Ah);
  number(s.amp_hours_charged_Ah);
  number(s.watt_hours_Wh);
  number(s.watt_hours_charged_Wh);
  number(s.battery_level);
  number(s.battery_wh);
  number(s.current_in_A);
  number(s.current_motor_A);
  number(s.speed_m_s);
  number(s.distance_m);
  number(s.distance_abs_m);
  integer(s.num_vescs);

  integer(-1);                              // ms_today_imu: no IMU reply
  for (int k = 0; k < 9; ++k) number(0.0);  // roll … gyroZ of IMU_VALUES()
  integer(-1);                              // gnss_posTime: no position
  for (int k = 0; k < 7; ++k) fixed(0.0);   // lat, lon, alt, gVel, vVel, hAcc, vAcc
  out += '\n';
}

VescToolLogWriter::VescToolLogWriter(const std::string& path) : out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw io::InputError(path, 0, 0, "", "cannot create file");
  out_ << vesc_tool_header();
}

void VescToolLogWriter::write(const VescToolRow& row) {
  line_.clear();
  append_vesc_tool_row(line_, row);
  out_ << line_;
}

}  // namespace rpem::sim
