// The drive-log CSV: every malformed input is rejected with file, line and column; what is written
// reads back bit-exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "rpem/core/frames.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/machine_config.hpp"
#include "support/seed.hpp"
#include "support/temp_file.hpp"

namespace rpem::io {
namespace {

const std::string kHeader = "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n";

/// Reads a log and returns the error message (empty when it reads cleanly).
std::string drive_log_error_of(const std::string& content) {
  test::TempFile f("log.csv", content);
  try {
    (void)read_drive_log(f.path());
  } catch (const DriveLogError& e) {
    return e.what();
  }
  return "";
}

TEST(DriveLog, ReadsAbcLogWithExtraAndOptionalColumns) {
  test::TempFile f("log.csv",
                   "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c,T_winding,comment,torque_cmd\n"
                   "0,0.1,31.4,220,10,-5,-5,1,-0.5,-0.5,25.5,7,3.5\n"
                   "0.000125,0.104,31.4,220,11,-5.5,-5.5,1.1,-0.55,-0.55,25.5,7,3.5\n");
  const auto rows = read_drive_log(f.path());
  ASSERT_EQ(rows.size(), 2U);
  EXPECT_EQ(rows[1].sample.t_ns, 125'000);
  EXPECT_EQ(rows[0].sample.voltage_frame, core::Frame::kAbc);
  EXPECT_DOUBLE_EQ(rows[1].sample.u_V[0], 11.0);
  EXPECT_DOUBLE_EQ(rows[1].sample.i_A[2], -0.55);
  EXPECT_EQ(rows[0].sample.t_winding_C, 25.5);
  EXPECT_FALSE(rows[0].t_magnet_C.has_value());
  EXPECT_EQ(rows[0].torque_cmd_Nm, 3.5);
}

TEST(DriveLog, ReadsDqOnlyLog) {
  test::TempFile f("log.csv",
                   "t,theta_el,omega_el,u_dc,u_d,u_q,i_d,i_q\n1,0,100,300,-20,80,-1,3\n2,0,100,300,-20,80,-1,3\n");
  DriveLogReader r(f.path());
  EXPECT_FALSE(r.layout().voltage_abc);
  EXPECT_TRUE(r.layout().current_dq);
  DriveLogRow row;
  ASSERT_TRUE(r.next(row));
  EXPECT_EQ(row.sample.voltage_frame, core::Frame::kDq);
  EXPECT_EQ(row.sample.current_frame, core::Frame::kDq);
  EXPECT_DOUBLE_EQ(row.sample.u_V[1], 80.0);
}

TEST(DriveLog, RotorFrameOnlyLogMayOmitAngleAndDcLink) {
  test::TempFile f("log.csv",
                   "t,omega_el,u_d,u_q,i_d,i_q,T_magnet\n0,2300,-125,37,-194,66,52\n2.5,2300,-126,35,-195,66,53\n");
  DriveLogReader r(f.path());
  EXPECT_FALSE(r.layout().angle);
  EXPECT_FALSE(r.layout().u_dc);
  DriveLogRow row;
  ASSERT_TRUE(r.next(row));
  EXPECT_EQ(row.sample.theta_el_rad, 0.0);
  EXPECT_EQ(row.sample.u_dc_V, 0.0);
  EXPECT_EQ(row.t_magnet_C, 52.0);
}

struct BadCase {
  const char* name;
  std::string content;
  const char* expected;  ///< substring of the message, including line and column
};

class MalformedLog : public ::testing::TestWithParam<BadCase> {};

TEST_P(MalformedLog, IsRejectedWithLineAndColumn) {
  const std::string msg = drive_log_error_of(GetParam().content);
  EXPECT_NE(msg.find(GetParam().expected), std::string::npos) << "message: " << msg;
  EXPECT_NE(msg.find("log.csv"), std::string::npos) << "message: " << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MalformedLog,
    ::testing::Values(
        BadCase{"empty", "", ":1: empty file"},
        BadCase{"byte_order_mark_alone", "\xEF\xBB\xBF\n",
                ":1: empty file: expected a header row (the file holds a byte-order mark alone)"},
        BadCase{"carriage_returns_alone", "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\r0,0,0,220,1,2,3,0,0,0\r",
                ":1: its lines end in a carriage return alone (classic Mac OS line endings)"},
        BadCase{"missing_time", "theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n", ":1: column t: required column"},
        // Windows Notepad's "Unicode": UTF-16 little-endian with its byte-order mark.
        BadCase{"utf16", std::string("\xFF\xFEt\0,\0t\0h\0\n\0", 12),
                ":1: the file is UTF-16 text (a byte-order mark FF FE or FE FF, or a zero byte beside each character"},
        BadCase{"no_current", "t,theta_el,omega_el,u_dc,u_a,u_b,u_c\n", "no current columns"},
        // Another layout, or rpem's with another separator: the header says which way out.
        BadCase{"another_layout", "time_s,Ia,Ib,Ic,Ua,Ub,Uc,speed\n",
                ":1: column t: required column is missing from the header; a CSV of another layout is read through a "
                "column map: --log-map MAP.yaml"},
        BadCase{"semicolons", "t;theta_el;omega_el;u_dc;u_a;u_b;u_c;i_a;i_b;i_c\n0;0;0;220;1;2;3;0;0;0\n",
                ":1: column t: required column is missing from the header; the header is one cell, "
                "\"t;theta_el;omega_el;u_dc;u_a;u_b;u_c;i_a;i_b;i_c\": are its cells separated by ';'? rpem reads ','"},
        BadCase{"no_angle_with_phases", "t,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n",
                ":1: column theta_el: required column is missing from the header (optional only when"},
        BadCase{"no_dc_link_with_phases", "t,theta_el,omega_el,u_d,u_q,i_a,i_b,i_c\n", ":1: column u_dc: required"},
        BadCase{"incomplete_abc", "t,theta_el,omega_el,u_dc,u_a,u_b,i_a,i_b,i_c\n", "column u_c: incomplete"},
        BadCase{"duplicate", "t,t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c\n", "column t: column appears twice"},
        BadCase{"non_numeric", kHeader + "0,0,0,220,1,2,3,abc,0,0\n", ":2:8: column i_a: 'abc' is not a number"},
        BadCase{"trailing_garbage", kHeader + "0,0,0,220,1,2,3,1.5x,0,0\n", ":2:8: column i_a: '1.5x'"},
        BadCase{"beyond_a_double", kHeader + "0,0,0,220,1,2,3,1e400,0,0\n",
                ":2:8: column i_a: '1e400' is beyond the range of a double (±1.8e308)"},
        // A control character in a cell is written out: a NUL would end the message where it is printed.
        BadCase{"nul_in_cell", kHeader + "0,0,0,220,1,2,3,1.5" + '\0' + "x,0,0\n",
                ":2:8: column i_a: '1.5\\x00x' is not a number"},
        BadCase{"nan", kHeader + "0,0,0,220,1,2,3,0,0,0\n0.1,0,0,nan,1,2,3,0,0,0\n", ":3:4: column u_dc: NaN"},
        BadCase{"inf", kHeader + "0,0,0,220,1,2,inf,0,0,0\n", ":2:7: column u_c: 'inf' is not finite"},
        BadCase{"empty_cell", kHeader + "0,0,,220,1,2,3,0,0,0\n", ":2:3: column omega_el: empty cell"},
        // An empty cell says whether the column stays empty: a logger that names a column it never records (a
        // third-party logger writing VESC Tool's header), one that stops recording it, one that fills it in late.
        BadCase{"column_never_recorded", kHeader + "0,0,,220,1,2,3,0,0,0\n0.1,0,,220,1,2,3,0,0,0\n0.2,0,,220,1,2,3,0,0,0\n",
                ":2:3: column omega_el: empty cell, and so on every row (3): the logger names the column in its header "
                "but recorded no value in it"},
        BadCase{"column_no_longer_recorded",
                kHeader + "0,0,1,220,1,2,3,0,0,0\n0.1,0,,220,1,2,3,0,0,0\n0.2,0,,220,1,2,3,0,0,0\n",
                ":3:3: column omega_el: empty cell, and so on every row from here to the end (2): the logger stopped"},
        BadCase{"column_recorded_late", kHeader + "0,0,,220,1,2,3,0,0,0\n0.1,0,,220,1,2,3,0,0,0\n0.2,0,5,220,1,2,3,0,0,0\n",
                ":2:3: column omega_el: empty cell (2 of the 3 rows from here leave it empty; line 4 is the first after "
                "it that has it: the logger filled it in after its first rows — delete the rows before it)"},
        BadCase{"time_backwards", kHeader + "0.2,0,0,220,1,2,3,0,0,0\n0.1,0,0,220,1,2,3,0,0,0\n",
                ":3:1: column t: time does not increase"},
        BadCase{"time_repeats", kHeader + "0.2,0,0,220,1,2,3,0,0,0\n0.2,0,0,220,1,2,3,0,0,0\n", ":3:1: column t"},
        // Distinct as doubles, the same integer nanosecond: the sample times would repeat.
        BadCase{"time_repeats_in_ns", kHeader + "0.2,0,0,220,1,2,3,0,0,0\n0.2000000000001,0,0,220,1,2,3,0,0,0\n",
                ":3:1: column t: time does not increase (by at least 1 ns)"},
        BadCase{"short_row", kHeader + "0,0,0,220,1,2,3,0,0\n", ":2: column *: row has 9 cells, header has 10"},
        // A header and nothing else, or only blank lines after it: no samples (every tool exits 65).
        BadCase{"header_only", kHeader, "log.csv:1: no samples: the header is followed by no data rows"},
        BadCase{"header_and_blank_lines", kHeader + "\n  \n\r\n", "log.csv:4: no samples"},
        // Values no drive produces (DriveLogLimits' absolute bounds), each with file:line:column.
        BadCase{"voltage_1e308", kHeader + "0,0,0,0,1e308,2,3,0,0,0\n",
                ":2:5: column u_a: 1e+308 V is beyond the plausible ±100000 V"},
        BadCase{"current_1e300", kHeader + "0,0,0,220,1,2,3,0,1e300,0\n",
                ":2:9: column i_b: 1e+300 A is beyond the plausible ±100000 A"},
        BadCase{"speed", kHeader + "0,0,-3e6,220,1,2,3,0,0,0\n",
                ":2:3: column omega_el: -3e+06 rad/s is beyond the plausible ±1e+06 rad/s"},
        BadCase{"dc_link", kHeader + "0,0,0,2e5,1,2,3,0,0,0\n", ":2:4: column u_dc: 200000 V is beyond"},
        BadCase{"angle", kHeader + "0,1e12,0,220,1,2,3,0,0,0\n", ":2:2: column theta_el: 1e+12 rad is beyond"},
        BadCase{"time_beyond_int64_ns", kHeader + "1e10,0,0,220,1,2,3,0,0,0\n", ":2:1: column t: 1e+10 s is beyond"},
        BadCase{"dq_voltage", "t,omega_el,u_d,u_q,i_d,i_q\n0,0,1,-1e20,0,0\n", ":2:4: column u_q: -1e+20 V is beyond"},
        BadCase{"dq_current_also_given",
                "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c,i_d,i_q\n0,0,0,220,1,2,3,0,0,0,0,1e6\n",
                ":2:12: column i_q: 1e+06 A is beyond"},
        BadCase{"temperature_below_absolute_zero", "t,omega_el,u_d,u_q,i_d,i_q,T_magnet\n0,0,1,1,0,0,-300\n",
                ":2:7: column T_magnet: -300 °C is outside the plausible [-273.15, 1000] °C"},
        BadCase{"torque", "t,omega_el,u_d,u_q,i_d,i_q,torque_cmd\n0,0,1,1,0,0,1e9\n", ":2:7: column torque_cmd: 1e+09 Nm"},
        // A command beyond twice the row's DC link (which must be at least 1 V to count).
        BadCase{"command_beyond_dc_link", kHeader + "0,0,0,220,1,2,3,0,0,0\n0.1,0,0,220,1,-441,3,0,0,0\n",
                ":3:6: column u_b: -441 V is more than 2 x this row's u_dc = 220 V"}),
    [](const auto& p) { return std::string(p.param.name); });

TEST(DriveLog, ValuesAtTheLimitsAreAccepted) {
  // Just inside every bound; a command of 2·u_dc where u_dc < 1 V is not held to the DC link.
  test::TempFile f("log.csv",
                   "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c,T_winding,torque_cmd\n"
                   "-9e9,-1e9,1e6,100000,1e5,-1e5,0,1e5,-1e5,0,-273.15,-1e7\n"
                   "0,0,0,0.5,200,0,0,0,0,0,1000,0\n"
                   "1,0,0,220,440,-440,0,0,0,0,25,0\n");
  EXPECT_EQ(read_drive_log(f.path()).size(), 3U);
}

TEST(DriveLog, MachineLimitsNarrowTheBoundsToTenTimesTheNamePlate) {
  // The paper's machine: I_b = √2·4.93 A, U_b = √2·400/√3 V, ω_b = 100π rad/s (docs/per-unit.md).
  core::MachineSi m;
  m.rated = {400.0, 4.93, 1000.0, 3};
  const DriveLogLimits l = machine_limits(m);
  EXPECT_NEAR(l.current_A.max_abs, 10.0 * std::sqrt(2.0) * 4.93, 1e-12);
  EXPECT_NEAR(l.voltage_V.max_abs, 10.0 * std::sqrt(2.0) * 400.0 / std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(l.speed_rad_s.max_abs, 10.0 * 100.0 * M_PI, 1e-9);
  EXPECT_EQ(l.angle_rad.max_abs, DriveLogLimits{}.angle_rad.max_abs);
  const std::string row_ok = "0,0,3141,3265,0,0,0,69.7,0,0\n";
  test::TempFile ok("ok.csv", kHeader + row_ok);
  EXPECT_EQ(read_drive_log(ok.path(), l).size(), 1U);
  test::TempFile bad("bad.csv", kHeader + row_ok + "1,0,0,220,0,0,0,0,0,-69.8\n");
  try {
    (void)read_drive_log(bad.path(), l);
    ADD_FAILURE() << "accepted 69.8 A against 10·I_b = 69.72 A";
  } catch (const DriveLogError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3:10: column i_c: -69.8 A is beyond the plausible ±69.7207 A (10 x the "
                                         "configured machine's rated peak phase current 6.972 A, machine.rated)"),
              std::string::npos)
        << e.what();
  }
  // The DC link is the inverter's: a link of 5 kV, above 10·U_b = 3266 V, is read; a command above 10·U_b is not.
  test::TempFile link("link.csv", kHeader + "0,0,0,5000,0,0,0,0,0,0\n");
  EXPECT_EQ(read_drive_log(link.path(), l).size(), 1U);
  EXPECT_EQ(l.dc_link_V.max_abs, DriveLogLimits{}.voltage_V.max_abs);
  test::TempFile command("command.csv", kHeader + "0,0,0,5000,3266.1,0,0,0,0,0\n");
  EXPECT_THROW((void)read_drive_log(command.path(), l), DriveLogError);
  // A name plate far above the absolute limits never widens them.
  m.rated = {1e5, 1e5, 1e6, 100};
  EXPECT_EQ(machine_limits(m).current_A.max_abs, DriveLogLimits{}.current_A.max_abs);
}

TEST(DriveLog, ReadsFromAStreamUnderAGivenName) {
  std::istringstream in(kHeader + "0,0,0,220,1,2,3,0,0,0\n0.1,0,0,220,1,2,x,0,0,0\n");
  DriveLogReader r(in, "memory.csv");
  DriveLogRow row;
  ASSERT_TRUE(r.next(row));
  try {
    (void)r.next(row);
    ADD_FAILURE() << "accepted 'x'";
  } catch (const DriveLogError& e) {
    EXPECT_EQ(std::string(e.what()), "memory.csv:3:7: column u_c: 'x' is not a number");
  }
}

TEST(DriveLog, MissingFileIsReported) { EXPECT_THROW((void)read_drive_log("/nonexistent/rpem.csv"), DriveLogError); }

TEST(DriveLog, WriteThenReadIsBitExact) {
  std::mt19937_64 rng(test::test_seed(31));
  std::normal_distribution<double> nd(0.0, 100.0);
  test::TempFile f("roundtrip.csv");
  DriveLogLayout layout;
  layout.t_magnet = true;
  std::vector<DriveLogRow> written;
  {
    DriveLogWriter w(f.path(), layout);
    for (int k = 0; k < 500; ++k) {
      DriveLogRow row;
      row.sample.t_ns = 125'000LL * k + 17;
      row.sample.theta_el_rad = core::wrap_angle(nd(rng));
      row.sample.omega_el_rad_s = nd(rng);
      row.sample.u_dc_V = 220.0 + nd(rng) * 1e-3;
      row.sample.u_V = {nd(rng) / 2, nd(rng) / 2, nd(rng) / 2};  // within 2·u_dc (DriveLogLimits)
      row.sample.i_A = {nd(rng) / 10, nd(rng) / 10, nd(rng) / 10};
      row.t_magnet_C = 20.0 + k * 1e-3;
      w.write(row);
      written.push_back(row);
    }
  }
  const auto read = read_drive_log(f.path());
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t k = 0; k < read.size(); ++k) {
    EXPECT_EQ(read[k].sample.t_ns, written[k].sample.t_ns);
    EXPECT_EQ(read[k].sample.theta_el_rad, written[k].sample.theta_el_rad);
    EXPECT_EQ(read[k].sample.omega_el_rad_s, written[k].sample.omega_el_rad_s);
    EXPECT_EQ(read[k].sample.u_dc_V, written[k].sample.u_dc_V);
    EXPECT_EQ(read[k].sample.u_V, written[k].sample.u_V);
    EXPECT_EQ(read[k].sample.i_A, written[k].sample.i_A);
    EXPECT_EQ(read[k].t_magnet_C, written[k].t_magnet_C);
  }
}

// A temperature sensor reads far more slowly than the phases are sampled (the native protocol's temperature frame
// every 100 ms; `rpem record --out`): the writer puts `nan` on the rows between readings, the reader takes it as
// no reading on that row, and every other row's value comes back bit-exactly.
TEST(DriveLog, TemperatureCellsBetweenReadingsRoundTripAsNoReading) {
  test::TempFile f("sparse.csv");
  DriveLogLayout layout;
  layout.t_winding = layout.t_magnet = layout.t_coolant = true;
  constexpr double kNoReading = std::numeric_limits<double>::quiet_NaN();
  {
    DriveLogWriter w(f.path(), layout);
    for (int k = 0; k < 10; ++k) {
      DriveLogRow row;
      row.sample.t_ns = 125'000LL * k;
      row.sample.u_dc_V = 48.0;
      row.sample.t_winding_C = k % 4 == 1 ? 60.0 + 0.1 * k : kNoReading;
      row.sample.t_coolant_C = k == 7 ? 31.4 : kNoReading;
      if (k == 3) row.t_magnet_C = 55.5;
      w.write(row);
    }
  }
  const auto read = read_drive_log(f.path());
  ASSERT_EQ(read.size(), 10U);
  for (int k = 0; k < 10; ++k) {
    const DriveLogRow& r = read[static_cast<std::size_t>(k)];
    if (k % 4 == 1) {
      EXPECT_EQ(r.sample.t_winding_C, 60.0 + 0.1 * k) << "row " << k;
    } else {
      EXPECT_TRUE(std::isnan(r.sample.t_winding_C)) << "row " << k;
    }
    EXPECT_EQ(std::isnan(r.sample.t_coolant_C), k != 7) << "row " << k;
    EXPECT_EQ(r.t_magnet_C.has_value(), k == 3) << "row " << k;
  }
  EXPECT_EQ(read[7].sample.t_coolant_C, 31.4);
  EXPECT_EQ(read[3].t_magnet_C, 55.5);
}

// Only a temperature's cell may say "no reading": the other quantities of a sample have a value on every row.
TEST(DriveLog, ANanOutsideATemperatureColumnIsStillRefused) {
  const std::string header = "t,theta_el,omega_el,u_dc,u_a,u_b,u_c,i_a,i_b,i_c,T_winding\n";
  EXPECT_EQ(drive_log_error_of(header + "0,0,0,220,1,2,3,0,0,0,nan\n0.1,0,0,220,1,2,3,0,0,0,25\n"), "");
  EXPECT_NE(drive_log_error_of(header + "0,0,0,220,1,2,3,nan,0,0,25\n").find(":2:8: column i_a: NaN"), std::string::npos);
  EXPECT_NE(drive_log_error_of(header + "0,0,nan,220,1,2,3,0,0,0,25\n").find(":2:3: column omega_el: NaN"),
            std::string::npos);
}

TEST(DriveLog, WriterDerivesRotorFrameColumnsWithPark) {
  test::TempFile f("dq.csv");
  DriveLogLayout layout;
  layout.voltage_dq = true;
  layout.current_dq = true;
  DriveLogRow row;
  row.sample.theta_el_rad = 0.4;
  const core::Vec2 i_dq(-1.0, 3.0);
  row.sample.i_A = core::inverse_clarke(core::inverse_park(i_dq, core::Rotation::of(0.4)));
  {
    DriveLogWriter w(f.path(), layout);
    w.write(row);
  }
  DriveLogReader r(f.path());
  DriveLogRow back;
  ASSERT_TRUE(r.next(back));
  EXPECT_TRUE(r.layout().current_dq);
  EXPECT_TRUE(r.layout().current_abc);
  // The reader prefers abc; the dq columns must agree with them.
  test::TempFile g("dq_only.csv");
  layout.current_abc = layout.voltage_abc = false;
  {
    DriveLogWriter w(g.path(), layout);
    w.write(row);
  }
  const auto rows = read_drive_log(g.path());
  EXPECT_NEAR(rows[0].sample.i_A[0], -1.0, 1e-12);
  EXPECT_NEAR(rows[0].sample.i_A[1], 3.0, 1e-12);
}

}  // namespace
}  // namespace rpem::io
