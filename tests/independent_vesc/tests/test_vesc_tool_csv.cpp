// The wire and VESC Tool's file, checked against what their sources say (README "The CSV"): the firmware's
// float-to-integer conversion, VESC Tool's division, the header of every version, QTextStream's numbers, the
// row's shape and ms_today's wrap at midnight.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "indep_vesc/values.hpp"
#include "indep_vesc/vesc_tool_csv.hpp"

namespace indep::vesc {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ';')) cells.push_back(cell);
  return cells;
}

TEST(IndepVescWire, FloatsTruncateTowardZeroAndNanIsZero) {
  EXPECT_EQ(wire_int32(12.3456f, 100.0f), 1234);
  EXPECT_EQ(wire_int32(-12.3456f, 100.0f), -1234);
  EXPECT_EQ(wire_int32(0.999f, 1.0f), 0);
  EXPECT_EQ(wire_int32(std::numeric_limits<float>::quiet_NaN(), 100.0f), 0);  // 0/0: no cycle since the last read
  EXPECT_EQ(wire_int32(1e12f, 1.0f), std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(wire_int16(48.27f, 10.0f), 482);
  EXPECT_EQ(wire_int16(3276.8f, 10.0f), -32768);  // 32768 keeps its low 16 bits
}

TEST(IndepVescWire, VescToolDividesTheIntegerByTheScale) {
  ValuesReply r;
  r.id = -3.21789f;
  r.iq = 27.4599f;
  r.vd = -1.23456f;
  r.vq = 11.8737f;
  r.rpm = 21000.7f;
  r.v_in = 48.29f;
  r.temp_motor = 67.86f;
  r.duty_now = 0.4567f;
  const McValues v = decode_values(r);
  EXPECT_DOUBLE_EQ(v.id, -321.0 / 100.0);
  EXPECT_DOUBLE_EQ(v.iq, 2745.0 / 100.0);
  EXPECT_DOUBLE_EQ(v.vd, -1234.0 / 1000.0);
  EXPECT_DOUBLE_EQ(v.vq, 11873.0 / 1000.0);
  EXPECT_DOUBLE_EQ(v.rpm, 21000.0);
  EXPECT_DOUBLE_EQ(v.v_in, 482.0 / 10.0);
  EXPECT_DOUBLE_EQ(v.temp_motor, 678.0 / 10.0);
  EXPECT_DOUBLE_EQ(v.duty_now, 456.0 / 1000.0);
}

// The headers, copied by hand from vescinterface.cpp's openRtLogFile at each version (vedderb/vesc_tool).
TEST(IndepVescCsv, HeadersAreVescToolsOfEachVersion) {
  const std::string base =
      "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
      "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
      "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;";
  const std::string gnss = "gnss_posTime;gnss_lat;gnss_lon;gnss_alt;gnss_gVel;gnss_vVel;gnss_hAcc;gnss_vAcc;";
  EXPECT_EQ(header_line(0), "");
  EXPECT_EQ(header_line(1), base);
  EXPECT_EQ(header_line(2), base + "d_axis_voltage;q_axis_voltage;" + gnss);
  EXPECT_EQ(header_line(3),
            base +
                "d_axis_voltage;q_axis_voltage;ms_today_setup;amp_hours_setup;amp_hours_charged_setup;"
                "watt_hours_setup;watt_hours_charged_setup;battery_level;battery_wh_tot;current_in_setup;"
                "current_motor_setup;speed_meters_per_sec;tacho_meters;tacho_abs_meters;num_vescs;ms_today_imu;"
                "roll;pitch;yaw;accX;accY;accZ;gyroX;gyroY;gyroZ;" +
                gnss);
  for (int v = 1; v <= 3; ++v) EXPECT_EQ(static_cast<int>(split(header_line(v)).size()), column_count(v));
  EXPECT_THROW(header_line(4), std::invalid_argument);
}

// QTextStream's default for a double is SmartNotation with precision 6: printf's %g in the C locale.
TEST(IndepVescCsv, NumbersAreQTextStreams) {
  EXPECT_EQ(qt_number(48.0), "48");
  EXPECT_EQ(qt_number(-3.21), "-3.21");
  EXPECT_EQ(qt_number(0.0001), "0.0001");
  EXPECT_EQ(qt_number(0.00001), "1e-05");
  EXPECT_EQ(qt_number(123456.0), "123456");
  EXPECT_EQ(qt_number(1234567.0), "1.23457e+06");
  EXPECT_EQ(qt_number(12.345678), "12.3457");
  EXPECT_EQ(qt_fixed8(0.0), "0.00000000");
}

TEST(IndepVescCsv, RowsHaveTheVersionsValuesEachFollowedByASemicolon) {
  RowContext r;
  r.ms_today = 45296789;
  r.values.v_in = 48.2;
  r.values.id = -3.21;
  r.values.iq = 27.45;
  r.values.rpm = 21000.0;
  r.values.vd = -1.234;
  r.values.vq = 11.873;
  r.values.tachometer = -12;
  r.ms_setup = 45296701;
  r.setup.num_vescs = 1;
  for (int v = 0; v <= 3; ++v) {
    const std::string line = row_line(v, r);
    ASSERT_EQ(line.back(), ';');
    const std::vector<std::string> cells = split(line);
    ASSERT_EQ(static_cast<int>(cells.size()), column_count(v)) << line;
    EXPECT_EQ(cells[0], "45296789");
    EXPECT_EQ(cells[1], "48.2");
    EXPECT_EQ(cells[9], "-3.21");
    EXPECT_EQ(cells[10], "27.45");
    EXPECT_EQ(cells[11], "21000");
    EXPECT_EQ(cells[17], "-12");
    if (v >= 2) {
      EXPECT_EQ(cells[22], "-1.234");
      EXPECT_EQ(cells[23], "11.873");
      EXPECT_EQ(cells[static_cast<std::size_t>(column_count(v) - 8)], "-1");          // gnss_posTime
      EXPECT_EQ(cells[static_cast<std::size_t>(column_count(v) - 7)], "0.00000000");  // gnss_lat, fixed from here
      EXPECT_EQ(cells.back(), "0.00000000");
    }
    if (v == 3) {
      EXPECT_EQ(cells[24], "45296701");  // ms_today_setup
      EXPECT_EQ(cells[36], "1");         // num_vescs
      EXPECT_EQ(cells[37], "-1");        // ms_today_imu
    }
  }
}

TEST(IndepVescCsv, MsTodayTruncatesAndWrapsAtMidnight) {
  EXPECT_EQ(ms_today(1000.0, 0.0019), 1001);
  EXPECT_EQ(ms_today(86'399'500.0, 0.4999), 86'399'999);
  EXPECT_EQ(ms_today(86'399'500.0, 0.5), 0);
  EXPECT_EQ(ms_today(86'399'500.0, 1.25), 750);
}

}  // namespace
}  // namespace indep::vesc
