#pragma once
// Test vectors of VESC Tool's realtime-data log, written from VESC Tool's own source (vedderb/vesc_tool,
// vescinterface.cpp), never from our code: each header copied column by column from openRtLogFile()
// (`os << "name" << ";"` per column, then "\n") at the commit that introduced it; rows as its
// valuesReceived handler writes them (each value followed by ';'; QTextStream's default notation).

#include <string>

namespace rpem::test::vesc_tool {

// 95f18604 (VESC Tool 1.17, 2019-09-03): the first header.
inline const std::string kHeader117 =
    "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
    "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
    "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;\n";
// 5986063b (2019-09-17, VT_VERSION 1.20 before its release): d/q voltages and GNSS added.
inline const std::string kHeader120Test =
    "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
    "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
    "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;d_axis_voltage;q_axis_voltage;"
    "gnss_posTime;gnss_lat;gnss_lon;gnss_alt;gnss_gVel;gnss_vVel;gnss_hAcc;gnss_vAcc;\n";
// 408f78fc (VESC Tool 1.20, 2019-09-27) and unchanged up to 426a4f8e (2026-07-29): setup and IMU added.
inline const std::string kHeader120 =
    "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
    "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
    "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;d_axis_voltage;q_axis_voltage;"
    "ms_today_setup;amp_hours_setup;amp_hours_charged_setup;watt_hours_setup;watt_hours_charged_setup;battery_level;"
    "battery_wh_tot;current_in_setup;current_motor_setup;speed_meters_per_sec;tacho_meters;tacho_abs_meters;num_vescs;"
    "ms_today_imu;roll;pitch;yaw;accX;accY;accZ;gyroX;gyroY;gyroZ;"
    "gnss_posTime;gnss_lat;gnss_lon;gnss_alt;gnss_gVel;gnss_vVel;gnss_hAcc;gnss_vAcc;\n";

/// One row of the 22 values every version writes first (v_in, temps, currents, erpm, …, vesc_id).
/// `tachometer`: the firmware's count of 60° steps (signed; tachometer_abs is left at 1300).
inline std::string values22(long ms, double v_in, double t_motor, double i_d, double i_q, double erpm,
                            long tachometer = 1234) {
  return std::to_string(ms) + ";" + std::to_string(v_in) + ";41.3;41.3;40.9;40.2;" + std::to_string(t_motor) + ";12.5;7.1;" +
         std::to_string(i_d) + ";" + std::to_string(i_q) + ";" + std::to_string(erpm) + ";0.31;0.0123;0;0.51;0;" +
         std::to_string(tachometer) + ";1300;178.5;0;17;";
}
/// A row of the 1.20 header: the 22 values, v_d, v_q, 13 setup, 10 IMU (their times −1: never received,
/// as VESC Tool writes them), 8 GNSS (posTime −1: no position).
/// `t_motor`: temp_motor, the motor sensor's °C (−100 where the firmware has no reading of it).
inline std::string row120_with_motor(long ms, double t_motor, double i_d, double i_q, double erpm, double v_d, double v_q,
                                     long tachometer = 1234) {
  return values22(ms, 40.1, t_motor, i_d, i_q, erpm, tachometer) + std::to_string(v_d) + ";" + std::to_string(v_q) + ";" +
         "-1;0;0;0;0;0;0;0;0;0;0;0;0;" + "-1;0;0;0;0;0;0;0;0;0;" + "-1;0.00000000;0.00000000;0;0;0;0;0;\n";
}
inline std::string row120(long ms, double i_d, double i_q, double erpm, double v_d, double v_q, long tachometer = 1234) {
  return row120_with_motor(ms, 55.0, i_d, i_q, erpm, v_d, v_q, tachometer);
}
inline std::string row120test(long ms, double i_d, double i_q, double erpm, double v_d, double v_q) {
  return values22(ms, 40.1, 55.0, i_d, i_q, erpm) + std::to_string(v_d) + ";" + std::to_string(v_q) + ";" +
         "-1;0.00000000;0.00000000;0;0;0;0;0;\n";
}

}  // namespace rpem::test::vesc_tool
