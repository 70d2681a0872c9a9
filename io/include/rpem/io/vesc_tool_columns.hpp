#pragma once
// The column names of VESC Tool's realtime-data log, in the groups and the order VescInterface::openRtLogFile
// writes them (vedderb/vesc_tool, vescinterface.cpp: `os << "name" << ";"` per column; the groups as
// 408f78fc, 2019-09-27, VESC Tool 1.20, left them, unchanged up to 426a4f8e, 2026-07-29). The one list
// of them: io's reader builds every header version from these groups (vesc_tool_log.cpp, with the commit
// that introduced each version) and sim's emulator writes the newest (sim/src/vesc_tool_log.cpp).
// docs/drive-log.md, "VESC Tool logs", lists the versions.

#include <algorithm>
#include <array>
#include <cstddef>
#include <string_view>

namespace rpem::io::vesc_tool {

/// The reply's values, which every version writes first (and VESC Tool 1.11–1.16 without a header).
inline constexpr std::array<std::string_view, 22> kValues{
    "ms_today",       "input_voltage",    "temp_mos_max",      "temp_mos_1",      "temp_mos_2",         "temp_mos_3",
    "temp_motor",     "current_motor",    "current_in",        "d_axis_current",  "q_axis_current",     "erpm",
    "duty_cycle",     "amp_hours_used",   "amp_hours_charged", "watt_hours_used", "watt_hours_charged", "tachometer",
    "tachometer_abs", "encoder_position", "fault_code",        "vesc_id"};
/// The reply's d/q voltages (since 5986063b).
inline constexpr std::array<std::string_view, 2> kDqVoltages{"d_axis_voltage", "q_axis_voltage"};
/// The last COMM_GET_VALUES_SETUP reply, its time first (since 408f78fc).
inline constexpr std::array<std::string_view, 13> kSetup{"ms_today_setup",
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
/// The last IMU reply, its time first (since 408f78fc).
inline constexpr std::array<std::string_view, 10> kImu{"ms_today_imu", "roll", "pitch", "yaw",   "accX",
                                                       "accY",         "accZ", "gyroX", "gyroY", "gyroZ"};
/// The position, its time first (since 5986063b).
inline constexpr std::array<std::string_view, 8> kGnss{"gnss_posTime", "gnss_lat",  "gnss_lon",  "gnss_alt",
                                                       "gnss_gVel",    "gnss_vVel", "gnss_hAcc", "gnss_vAcc"};

/// The groups one after the other.
template <std::size_t... N>
constexpr std::array<std::string_view, (N + ...)> join(const std::array<std::string_view, N>&... groups) {
  std::array<std::string_view, (N + ...)> out{};
  auto next = out.begin();
  ((next = std::copy(groups.begin(), groups.end(), next)), ...);
  return out;
}

/// The header of VESC Tool 1.20 and later (408f78fc), the newest version.
inline constexpr auto kColumns120 = join(kValues, kDqVoltages, kSetup, kImu, kGnss);

}  // namespace rpem::io::vesc_tool
