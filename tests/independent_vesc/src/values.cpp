#include "indep_vesc/values.hpp"

#include <cmath>
#include <limits>

namespace indep::vesc {

std::int32_t wire_int32(float value, float scale) {
  const float x = value * scale;  // single precision, as the firmware multiplies
  if (std::isnan(x)) return 0;
  if (x >= 2147483648.0f) return std::numeric_limits<std::int32_t>::max();
  if (x <= -2147483648.0f) return std::numeric_limits<std::int32_t>::min();
  return static_cast<std::int32_t>(x);  // toward zero
}

std::int16_t wire_int16(float value, float scale) {
  const auto low = static_cast<std::uint16_t>(static_cast<std::uint32_t>(wire_int32(value, scale)) & 0xFFFFu);
  return static_cast<std::int16_t>(low);
}

namespace {

double d32(float v, float scale) { return static_cast<double>(wire_int32(v, scale)) / static_cast<double>(scale); }
double d16(float v, float scale) { return static_cast<double>(wire_int16(v, scale)) / static_cast<double>(scale); }

}  // namespace

McValues decode_values(const ValuesReply& r) {
  McValues v;
  v.temp_mos = d16(r.temp_mos, 1e1f);
  v.temp_motor = d16(r.temp_motor, 1e1f);
  v.current_motor = d32(r.current_motor, 1e2f);
  v.current_in = d32(r.current_in, 1e2f);
  v.id = d32(r.id, 1e2f);
  v.iq = d32(r.iq, 1e2f);
  v.duty_now = d16(r.duty_now, 1e3f);
  v.rpm = d32(r.rpm, 1e0f);
  v.v_in = d16(r.v_in, 1e1f);
  v.amp_hours = d32(r.amp_hours, 1e4f);
  v.amp_hours_charged = d32(r.amp_hours_charged, 1e4f);
  v.watt_hours = d32(r.watt_hours, 1e4f);
  v.watt_hours_charged = d32(r.watt_hours_charged, 1e4f);
  v.tachometer = r.tachometer;
  v.tachometer_abs = r.tachometer_abs;
  v.fault_code = r.fault_code;
  v.position = d32(r.pid_pos, 1e6f);
  v.vesc_id = r.controller_id;
  v.temp_mos_1 = d16(r.temp_mos_1, 1e1f);
  v.temp_mos_2 = d16(r.temp_mos_2, 1e1f);
  v.temp_mos_3 = d16(r.temp_mos_3, 1e1f);
  v.vd = d32(r.vd, 1e3f);
  v.vq = d32(r.vq, 1e3f);
  return v;
}

SetupValues decode_setup(const SetupReply& r) {
  SetupValues v;
  v.current_motor = d32(r.current_tot, 1e2f);
  v.current_in = d32(r.current_in_tot, 1e2f);
  v.speed = d32(r.speed, 1e3f);
  v.battery_level = d16(r.battery_level, 1e3f);
  v.amp_hours = d32(r.amp_hours, 1e4f);
  v.amp_hours_charged = d32(r.amp_hours_charged, 1e4f);
  v.watt_hours = d32(r.watt_hours, 1e4f);
  v.watt_hours_charged = d32(r.watt_hours_charged, 1e4f);
  v.tachometer = d32(r.distance, 1e3f);
  v.tachometer_abs = d32(r.distance_abs, 1e3f);
  v.num_vescs = r.num_vescs;
  v.battery_wh = d32(r.battery_wh, 1e3f);
  return v;
}

}  // namespace indep::vesc
