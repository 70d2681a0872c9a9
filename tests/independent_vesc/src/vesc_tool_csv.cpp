#include "indep_vesc/vesc_tool_csv.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace indep::vesc {

namespace {

constexpr const char* kBase[] = {
    "ms_today",       "input_voltage",    "temp_mos_max",      "temp_mos_1",      "temp_mos_2",         "temp_mos_3",
    "temp_motor",     "current_motor",    "current_in",        "d_axis_current",  "q_axis_current",     "erpm",
    "duty_cycle",     "amp_hours_used",   "amp_hours_charged", "watt_hours_used", "watt_hours_charged", "tachometer",
    "tachometer_abs", "encoder_position", "fault_code",        "vesc_id"};
constexpr const char* kDq[] = {"d_axis_voltage", "q_axis_voltage"};
constexpr const char* kSetup[] = {"ms_today_setup",
                                  "amp_hours_setup",
                                  "amp_hours_charged_setup",
                                  "watt_hours_setup",
                                  "watt_hours_charged_setup",
                                  "battery_level",
                                  "battery_wh_tot",
                                  "current_in_setup",
                                  "current_motor_setup",
                                  "speed_meters_per_sec",
                                  "tacho_meters",
                                  "tacho_abs_meters",
                                  "num_vescs"};
constexpr const char* kImu[] = {"ms_today_imu", "roll", "pitch", "yaw", "accX", "accY", "accZ", "gyroX", "gyroY", "gyroZ"};
constexpr const char* kGnss[] = {"gnss_posTime", "gnss_lat",  "gnss_lon",  "gnss_alt",
                                 "gnss_gVel",    "gnss_vVel", "gnss_hAcc", "gnss_vAcc"};

void check(int version) {
  if (version < 0 || version > kNewestHeaderVersion) {
    throw std::invalid_argument("VESC Tool header version " + std::to_string(version) + " (known: 0, 1, 2, 3)");
  }
}

template <std::size_t N>
void names(std::string& s, const char* const (&list)[N]) {
  for (const char* n : list) {
    s += n;
    s += ';';
  }
}

void put(std::string& s, const std::string& v) {
  s += v;
  s += ';';
}
void put(std::string& s, double v) { put(s, qt_number(v)); }
void put_int(std::string& s, std::int64_t v) { put(s, std::to_string(v)); }

}  // namespace

std::string header_line(int version) {
  check(version);
  std::string s;
  if (version == 0) return s;
  names(s, kBase);
  if (version >= 2) names(s, kDq);
  if (version >= 3) {
    names(s, kSetup);
    names(s, kImu);
  }
  if (version >= 2) names(s, kGnss);
  return s;
}

int column_count(int version) {
  check(version);
  return version <= 1 ? 22 : version == 2 ? 32 : 55;
}

bool clock_is_utc(int version) {
  check(version);
  return version >= 2;
}

std::string qt_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string qt_fixed8(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.8f", v);
  return buf;
}

std::int64_t ms_today(double start_ms_today, double t_s) {
  constexpr std::int64_t kDay = 86'400'000;
  const auto ms = static_cast<std::int64_t>(std::floor(start_ms_today + t_s * 1000.0));
  return ((ms % kDay) + kDay) % kDay;
}

std::string row_line(int version, const RowContext& r) {
  check(version);
  const McValues& v = r.values;
  std::string s;
  put_int(s, r.ms_today);
  put(s, v.v_in);
  put(s, v.temp_mos);
  put(s, v.temp_mos_1);
  put(s, v.temp_mos_2);
  put(s, v.temp_mos_3);
  put(s, v.temp_motor);
  put(s, v.current_motor);
  put(s, v.current_in);
  put(s, v.id);
  put(s, v.iq);
  put(s, v.rpm);
  put(s, v.duty_now);
  put(s, v.amp_hours);
  put(s, v.amp_hours_charged);
  put(s, v.watt_hours);
  put(s, v.watt_hours_charged);
  put_int(s, v.tachometer);
  put_int(s, v.tachometer_abs);
  put(s, v.position);
  put_int(s, v.fault_code);
  put_int(s, v.vesc_id);
  if (version <= 1) return s;
  put(s, v.vd);
  put(s, v.vq);
  if (version >= 3) {
    const SetupValues& u = r.setup;
    put_int(s, r.ms_setup);
    put(s, u.amp_hours);
    put(s, u.amp_hours_charged);
    put(s, u.watt_hours);
    put(s, u.watt_hours_charged);
    put(s, u.battery_level);
    put(s, u.battery_wh);
    put(s, u.current_in);
    put(s, u.current_motor);
    put(s, u.speed);
    put(s, u.tachometer);
    put(s, u.tachometer_abs);
    put_int(s, u.num_vescs);
    put_int(s, -1);                           // ms_today_imu: no IMU polled
    for (int k = 0; k < 9; ++k) put(s, 0.0);  // roll … gyroZ of a default IMU_VALUES
  }
  put_int(s, -1);                                      // gnss_posTime: no position source
  for (int k = 0; k < 7; ++k) put(s, qt_fixed8(0.0));  // lat, lon (fixed, 8) and the rest, still fixed
  return s;
}

}  // namespace indep::vesc
