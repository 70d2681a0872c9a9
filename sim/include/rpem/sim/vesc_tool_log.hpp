#pragma once
// The realtime-data log VESC Tool writes while "log to file" is on (`rpem sim --vesc-tool-out`;
// docs/scenarios.md, "VESC Tool logs"). Everything here follows VESC Tool's source, vedderb/vesc_tool
// vescinterface.cpp at 426a4f8e (2026-07-29), unchanged since 408f78fc (2019-09-27, VESC Tool 1.20):
//   - VescInterface::openRtLogFile writes the header: 55 names, each followed by ';', then '\n' (kColumns);
//   - the Commands::valuesReceived handler writes one row per COMM_GET_VALUES reply, on a fresh QTextStream:
//     ms_today is QDateTime::currentDateTimeUtc().time().msecsSinceStartOfDay() (UTC milliseconds since
//     midnight, wrapping there), then the reply's fields as Commands decodes them (commands.cpp: the integer
//     divided by the firmware's scale), the last COMM_GET_VALUES_SETUP reply (its time, or -1 before the
//     first), the last IMU reply (-1 and zeros: not polled here) and the position (-1 and zeros: none);
//   - each value followed by ';', the row by '\n'. Doubles in QTextStream's default notation (SmartNotation,
//     precision 6, C locale: printf's %g, a negative zero written 0), integers in decimal; the stream is set
//     to Qt::fixed with precision 8 at the latitude, so the latitude and everything after it in the row —
//     longitude, altitude, the two speeds and the two accuracies — come out fixed with 8 decimals.
// Not a reader: the reader of these files is io/'s, written from VESC Tool's source separately.

#include <array>
#include <cstdint>
#include <fstream>
#include <string>

#include "rpem/can/vesc.hpp"

namespace rpem::sim {

/// COMM_GET_VALUES_SETUP as VESC Tool decodes it (SETUP_VALUES; the columns ending _setup and after).
struct VescSetupValues {
  double amp_hours_Ah = 0.0, amp_hours_charged_Ah = 0.0;
  double watt_hours_Wh = 0.0, watt_hours_charged_Wh = 0.0;
  double battery_level = 0.0;  ///< 0–1
  double battery_wh = 0.0;     ///< energy left
  double current_in_A = 0.0, current_motor_A = 0.0;
  double speed_m_s = 0.0;
  double distance_m = 0.0, distance_abs_m = 0.0;  ///< SETUP_VALUES tachometer, tachometer_abs
  int num_vescs = 0;
};

/// One row of the log.
struct VescToolRow {
  std::int32_t ms_today = 0;
  can::vesc::Values values;          ///< COMM_GET_VALUES as decoded (every field)
  std::int32_t ms_today_setup = -1;  ///< -1: no setup reply yet (then `setup` is all zeros)
  VescSetupValues setup;
};

/// The header's names, in order (openRtLogFile).
inline constexpr std::array<const char*, 55> kVescToolColumns = {"ms_today",
                                                                 "input_voltage",
                                                                 "temp_mos_max",
                                                                 "temp_mos_1",
                                                                 "temp_mos_2",
                                                                 "temp_mos_3",
                                                                 "temp_motor",
                                                                 "current_motor",
                                                                 "current_in",
                                                                 "d_axis_current",
                                                                 "q_axis_current",
                                                                 "erpm",
                                                                 "duty_cycle",
                                                                 "amp_hours_used",
                                                                 "amp_hours_charged",
                                                                 "watt_hours_used",
                                                                 "watt_hours_charged",
                                                                 "tachometer",
                                                                 "tachometer_abs",
                                                                 "encoder_position",
                                                                 "fault_code",
                                                                 "vesc_id",
                                                                 "d_axis_voltage",
                                                                 "q_axis_voltage",
                                                                 "ms_today_setup",
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
                                                                 "num_vescs",
                                                                 "ms_today_imu",
                                                                 "roll",
                                                                 "pitch",
                                                                 "yaw",
                                                                 "accX",
                                                                 "accY",
                                                                 "accZ",
                                                                 "gyroX",
                                                                 "gyroY",
                                                                 "gyroZ",
                                                                 "gnss_posTime",
                                                                 "gnss_lat",
                                                                 "gnss_lon",
                                                                 "gnss_alt",
                                                                 "gnss_gVel",
                                                                 "gnss_vVel",
                                                                 "gnss_hAcc",
                                                                 "gnss_vAcc"};

/// Milliseconds in a day: ms_today wraps here.
inline constexpr std::int64_t kMsPerDay = 86'400'000;

/// QTextStream's default output of a double (SmartNotation, precision 6, C locale).
void append_qt_double(std::string& out, double v);
/// QTextStream's output of a double after Qt::fixed and qSetRealNumberPrecision(8).
void append_qt_fixed8(std::string& out, double v);

/// The header line, '\n' included.
[[nodiscard]] std::string vesc_tool_header();
/// One row, '\n' included.
void append_vesc_tool_row(std::string& out, const VescToolRow& row);

class VescToolLogWriter {
 public:
  explicit VescToolLogWriter(const std::string& path);
  void write(const VescToolRow& row);

 private:
  std::ofstream out_;
  std::string line_;
};

}  // namespace rpem::sim
