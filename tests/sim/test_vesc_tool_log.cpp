// VESC Tool's realtime-data log as `rpem sim --vesc-tool-out` writes it, against a test vector written here
// from VESC Tool's source alone (vedderb/vesc_tool vescinterface.cpp at 426a4f8e: openRtLogFile's header; the
// Commands::valuesReceived handler's row; commands.cpp's decoding; Qt's QTextStream defaults — SmartNotation,
// precision 6, the C locale, exponents of two digits, a negative zero written 0 — and the Qt::fixed,
// qSetRealNumberPrecision(8) set at the latitude, which holds for the rest of the row), and the session's
// reads: every seed reproduces its log, intervals and losses as configured, windows contiguous, values on
// the wire's grid, midnight wrapping.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "rpem/sim/vesc_tool_log.hpp"
#include "rpem/sim/vesc_tool_session.hpp"

namespace rpem::sim {
namespace {

// The header, typed from openRtLogFile: each name followed by ";", then "\n".
constexpr const char* kHeader =
    "ms_today;input_voltage;temp_mos_max;temp_mos_1;temp_mos_2;temp_mos_3;temp_motor;current_motor;current_in;"
    "d_axis_current;q_axis_current;erpm;duty_cycle;amp_hours_used;amp_hours_charged;watt_hours_used;"
    "watt_hours_charged;tachometer;tachometer_abs;encoder_position;fault_code;vesc_id;d_axis_voltage;"
    "q_axis_voltage;ms_today_setup;amp_hours_setup;amp_hours_charged_setup;watt_hours_setup;"
    "watt_hours_charged_setup;battery_level;battery_wh_tot;current_in_setup;current_motor_setup;"
    "speed_meters_per_sec;tacho_meters;tacho_abs_meters;num_vescs;ms_today_imu;roll;pitch;yaw;accX;accY;accZ;"
    "gyroX;gyroY;gyroZ;gnss_posTime;gnss_lat;gnss_lon;gnss_alt;gnss_gVel;gnss_vVel;gnss_hAcc;gnss_vAcc;\n";

TEST(VescToolLog, HeaderIsVescToolsOwn) { EXPECT_EQ(vesc_tool_header(), kHeader); }

TEST(VescToolLog, RowIsWrittenAsVescToolWritesIt) {
  VescToolRow r;
  can::vesc::Values& v = r.values;
  // Values as Commands decodes them: the firmware's integers over their scales.
  r.ms_today = 45296789;  // 12:34:56.789 UTC
  v.v_in_V = 482 / 1e1;   // float16 ×10
  v.temp_fet_C = 413 / 1e1;
  v.temp_mos_C = {413 / 1e1, 409 / 1e1, 398 / 1e1};
  v.temp_motor_C = 678 / 1e1;
  v.current_motor_A = 2745 / 1e2;  // float32 ×100
  v.current_in_A = 1234 / 1e2;
  v.i_d_A = -321 / 1e2;
  v.i_q_A = 2745 / 1e2;
  v.erpm = 1234567 / 1e0;  // 7 digits: exponent form at precision 6
  v.duty = 354 / 1e3;
  v.amp_hours_Ah = 12345 / 1e4;
  v.amp_hours_charged_Ah = 1 / 1e4;  // 0.0001: fixed (exponent −4)
  v.watt_hours_Wh = 1234567 / 1e4;   // 123.4567: six significant digits
  v.watt_hours_charged_Wh = 0 / 1e4;
  v.tachometer = -123456;
  v.tachometer_abs = 234567;
  v.pid_pos_deg = 12 / 1e6;  // 1.2e-05: exponent form (exponent −5), two-digit exponent
  v.fault = 0;
  v.controller_id = 17;
  v.v_d_V = -0.0;  // a negative zero prints as 0
  v.v_q_V = 11873 / 1e3;
  r.ms_today_setup = 45296701;
  VescSetupValues& s = r.setup;
  s.amp_hours_Ah = 12345 / 1e4;
  s.amp_hours_charged_Ah = 1 / 1e4;
  s.watt_hours_Wh = 1234567 / 1e4;
  s.watt_hours_charged_Wh = 0.0;
  s.battery_level = 873 / 1e3;
  s.battery_wh = 123456789 / 1e3;  // 123456.789 → 123457
  s.current_in_A = 1234 / 1e2;
  s.current_motor_A = 2745 / 1e2;
  s.speed_m_s = 9876 / 1e3;
  s.distance_m = 1000000000 / 1e3;    // 1e+06
  s.distance_abs_m = 98765432 / 1e3;  // 98765.4
  s.num_vescs = 1;
  const std::string expected =
      "45296789;48.2;41.3;41.3;40.9;39.8;67.8;27.45;12.34;-3.21;27.45;1.23457e+06;0.354;1.2345;0.0001;123.457;0;"
      "-123456;234567;1.2e-05;0;17;0;11.873;"
      "45296701;1.2345;0.0001;123.457;0;0.873;123457;12.34;27.45;9.876;1e+06;98765.4;1;"
      "-1;0;0;0;0;0;0;0;0;0;"
      "-1;0.00000000;0.00000000;0.00000000;0.00000000;0.00000000;0.00000000;0.00000000;\n";
  std::string line;
  append_vesc_tool_row(line, r);
  EXPECT_EQ(line, expected);
  EXPECT_EQ(std::count(line.begin(), line.end(), ';'), 55);  // one per column, as in the header
}

TEST(VescToolLog, BeforeTheFirstSetupReplyItsColumnsAreVescToolsDefaults) {
  VescToolRow r;  // SETUP_VALUES(): zeros; msSetup −1
  r.values.v_in_V = 48.0;
  std::string line;
  append_vesc_tool_row(line, r);
  EXPECT_NE(line.find(";-1;0;0;0;0;0;0;0;0;0;0;0;0;-1;"), std::string::npos) << line;
}

Scenario short_scenario(double duration_s) {
  Scenario s = load_scenario(std::string(RPEM_TEST_SOURCE_DIR) + "/scenarios/vesc-6374.yaml");
  s.duration_s = duration_s;
  s.warmup_s = 0.02;
  return s;
}

struct Logged {
  std::vector<std::string> lines;
  std::vector<VescToolTruth> truth;
  std::vector<VescToolRow> rows;
};

Logged log_of(const Scenario& s, const VescToolLink& link) {
  VescToolSession session(s, link);
  Logged out;
  VescToolRow row;
  VescToolTruth truth;
  while (session.next(row, truth)) {
    std::string line;
    append_vesc_tool_row(line, row);
    out.lines.push_back(line);
    out.truth.push_back(truth);
    out.rows.push_back(row);
  }
  return out;
}

TEST(VescToolSession, EverySeedReproducesItsLog) {
  const Scenario s = short_scenario(3.0);
  VescToolLink link;
  link.seed = 7;
  link.loss = 0.05;
  const Logged a = log_of(s, link), b = log_of(s, link);
  EXPECT_EQ(a.lines, b.lines);
  link.seed = 8;
  const Logged c = log_of(s, link);
  EXPECT_NE(a.lines, c.lines);
}

TEST(VescToolSession, RowsComeAtTheLinksIntervalsAndEachAveragesItsWholeWindow) {
  const Scenario s = short_scenario(20.0);
  VescToolLink link;
  link.rate_Hz = 11.0;
  link.jitter = 0.5;
  link.loss = 0.03;
  link.seed = 3;
  const Logged log = log_of(s, link);
  ASSERT_GT(log.rows.size(), 100U);  // 11 Hz, less 1 s per lost poll
  const double period_ms = 1e3 / link.rate_Hz;
  int lost = 0, contiguous = 0;
  for (std::size_t k = 1; k < log.rows.size(); ++k) {
    const VescToolTruth& t = log.truth[k];
    const VescToolTruth& before = log.truth[k - 1];
    const double gap_ms = 1e-6 * static_cast<double>(t.t_ns - before.t_ns);
    if (t.lost_before == 0) {
      // (1 ± jitter)/rate, read at the first control cycle boundary (80 µs) at or after the poll.
      EXPECT_GE(gap_ms, (1.0 - link.jitter) * period_ms - 0.1);
      EXPECT_LE(gap_ms, (1.0 + link.jitter) * period_ms + 0.1);
      EXPECT_EQ(t.window_start_ns, before.t_ns);  // the window starts at the previous row's read
      ++contiguous;
    } else {
      EXPECT_GE(gap_ms, 1e3 * link.timeout_s * t.lost_before);  // VESC Tool's timeout per lost poll
      lost += t.lost_before;
    }
    // Every control cycle of the window, once: (t − start)/T_c of them.
    EXPECT_NEAR(t.cycles, static_cast<double>(t.t_ns - t.window_start_ns) / 80e3, 1.0);
    // ms_today is the read's UTC millisecond of the day.
    EXPECT_EQ(log.rows[k].ms_today, static_cast<std::int32_t>(link.start_ms_today + t.t_ns / 1'000'000));
    // The previous poll's setup reply, stamped with its own time.
    if (t.lost_before == 0) {
      EXPECT_EQ(log.rows[k].ms_today_setup, log.rows[k - 1].ms_today);
    }
    // On the wire's grid: float32 ×100 currents, ×1000 voltages.
    const can::vesc::Values& v = log.rows[k].values;
    EXPECT_NEAR(v.i_q_A * 100.0, std::round(v.i_q_A * 100.0), 1e-6);
    EXPECT_NEAR(v.v_q_V * 1000.0, std::round(v.v_q_V * 1000.0), 1e-6);
  }
  EXPECT_GT(lost, 0);
  EXPECT_GT(contiguous, 100);
  EXPECT_EQ(log.rows.front().ms_today_setup, -1);  // no setup reply before the first row
}

TEST(VescToolSession, MsTodayWrapsAtMidnight) {
  VescToolLink link;
  link.start_ms_today = kMsPerDay - 1000;  // 23:59:59.000 UTC
  link.loss = 0.0;
  const Logged log = log_of(short_scenario(2.5), link);
  bool wrapped = false;
  for (std::size_t k = 1; k < log.rows.size(); ++k) {
    if (log.rows[k].ms_today < log.rows[k - 1].ms_today) {
      EXPECT_FALSE(wrapped);
      wrapped = true;
      EXPECT_LT(log.rows[k].ms_today, 200);
      EXPECT_GT(log.rows[k - 1].ms_today, kMsPerDay - 200);
    }
    EXPECT_GE(log.rows[k].ms_today, 0);
    EXPECT_LT(log.rows[k].ms_today, kMsPerDay);
  }
  EXPECT_TRUE(wrapped);
}

}  // namespace
}  // namespace rpem::sim
