// VESC Tool's realtime-data log read as VESC Tool writes it: headers and rows from VESC Tool's own source
// (tests/support/vesc_tool_vectors.hpp), none produced by our code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "rpem/can/vesc.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/vesc_tool_log.hpp"
#include "support/temp_file.hpp"
#include "support/vesc_tool_vectors.hpp"

namespace rpem::io {
namespace {

using namespace test::vesc_tool;

std::string vesc_tool_error_of(const std::string& content) {
  test::TempFile f("vesc.csv", content);
  try {
    const LogSource s = log_source(f.path());
    (void)read_averaged_log(f.path(), s.map, DriveLogLimits{});
  } catch (const DriveLogError& e) {
    return e.what();
  }
  return "";
}

TEST(VescToolLog, EveryHeaderVersionIsIdentified) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {kHeader117, "1.17 to 1.19"}, {kHeader120Test, "1.20 test builds"}, {kHeader120, "1.20 and later"}};
  ASSERT_EQ(vesc_tool_headers().size(), cases.size());
  for (const auto& [header, versions] : cases) {
    std::vector<std::string> cells;
    std::string h = header.substr(0, header.size() - 2);  // without the trailing ";\n"
    for (std::size_t start = 0;;) {
      const std::size_t sep = h.find(';', start);
      cells.push_back(h.substr(start, sep - start));
      if (sep == std::string::npos) break;
      start = sep + 1;
    }
    const VescToolHeader* v = identify_vesc_tool_header(cells);
    ASSERT_NE(v, nullptr) << versions;
    EXPECT_EQ(std::string(v->versions), versions);
  }
}

TEST(VescToolLog, ReadsTheCurrentHeaderAsAveragedSamplesSinceThePreviousRow) {
  // GIVEN three reads 90 and 110 ms apart WHEN read THEN the first row opens the window and each sample
  // holds the means since the previous row, the speed electrical (erpm·2π/60) and the window's mean: erpm is
  // the PLL's at each read, lagging a ramp by k_p/k_i = 2000/30000 s, so the mean is
  // erpm_k + (erpm_k − erpm_{k−1})·(τ/h − ½) (docs/derivations.md §13, "Speed at the read").
  test::TempFile f("vesc.csv", kHeader120 + row120(45000000, -0.5, 3.2, 6000, -0.31, 8.7) +
                                   row120(45000090, -1.25, 10.5, 6100, -0.9, 9.25) +
                                   row120(45000200, -1.5, 11.0, 6200, -1.0, 9.5));
  const LogSource source = log_source(f.path());
  EXPECT_TRUE(source.averaged());
  EXPECT_NE(source.format.find("VESC Tool 1.20 and later"), std::string::npos) << source.format;
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 2U);
  EXPECT_EQ(read.rows, 3U);
  EXPECT_EQ(read.opening_rows, 1U);
  EXPECT_EQ(s[0].t_start_ns, 45'000'000'000'000);
  EXPECT_EQ(s[0].t_ns, 45'000'090'000'000);
  EXPECT_EQ(s[1].t_start_ns, s[0].t_ns);
  EXPECT_DOUBLE_EQ(s[0].i_dq_A[0], -1.25);
  EXPECT_DOUBLE_EQ(s[0].i_dq_A[1], 10.5);
  EXPECT_DOUBLE_EQ(s[0].u_dq_V[0], -0.9);
  EXPECT_DOUBLE_EQ(s[0].u_dq_V[1], 9.25);
  constexpr double kTau = 2000.0 / 30000.0;
  EXPECT_NEAR(s[0].omega_el_rad_s, (6100.0 + 100.0 * (kTau / 0.090 - 0.5)) * 2.0 * std::numbers::pi / 60.0, 1e-9);
  EXPECT_NEAR(s[1].omega_el_rad_s, (6200.0 + 100.0 * (kTau / 0.110 - 0.5)) * 2.0 * std::numbers::pi / 60.0, 1e-9);
  // The larger |speed| at each window's two reads (docs/derivations.md §13, "A stall's rocking").
  EXPECT_DOUBLE_EQ(s[0].omega_el_at_reads_max_rad_s, 6100.0 * 2.0 * std::numbers::pi / 60.0);
  EXPECT_DOUBLE_EQ(s[1].omega_el_at_reads_max_rad_s, 6200.0 * 2.0 * std::numbers::pi / 60.0);
  EXPECT_NE(describe(source, read).find("mean speed rebuilt from the PLL speeds at its two reads (lag 66.67 ms)"),
            std::string::npos)
      << describe(source, read);
  EXPECT_DOUBLE_EQ(s[0].u_dc_V, 40.1);
  EXPECT_DOUBLE_EQ(s[0].t_winding_C, 55.0);
  EXPECT_DOUBLE_EQ(s[0].t_drive_C, 41.3);
  EXPECT_TRUE(std::isnan(s[0].t_magnet_C));
  EXPECT_TRUE(read.layout.u_dc && read.layout.t_winding && read.layout.t_drive && !read.layout.t_magnet);
}

/// `csv` (';'-separated, a header line first) without the columns named `drop`, from the header and every row.
std::string without_vesc_columns(const std::string& csv, const std::vector<std::string>& drop) {
  std::vector<std::vector<std::string>> lines;
  std::size_t from = 0;
  while (from < csv.size()) {
    const std::size_t end = csv.find('\n', from);
    const std::string line = csv.substr(from, end - from);
    std::vector<std::string> cells;
    std::size_t c = 0;
    while (c <= line.size()) {
      const std::size_t semi = std::min(line.find(';', c), line.size());
      cells.push_back(line.substr(c, semi - c));
      c = semi + 1;
    }
    lines.push_back(cells);
    from = end == std::string::npos ? csv.size() : end + 1;
  }
  std::string out;
  for (const auto& cells : lines) {
    for (std::size_t k = 0; k < cells.size(); ++k) {
      if (std::find(drop.begin(), drop.end(), lines[0][k]) != drop.end()) continue;
      out += cells[k] + (k + 1 < cells.size() ? ";" : "");
    }
    out += '\n';
  }
  return out;
}

TEST(VescToolLog, ALogCutDownWithoutItsTemperaturesIsReadWithoutThem) {
  // A new user's walk (2026-12-06): temp_motor and temp_mos_max cut out of a log (a spreadsheet's copy) were refused
  // as "rpem needs it", though nothing but the thermal fusion reads them. GIVEN the current header's three reads with
  // both columns removed WHEN read THEN the same samples as the whole log's, and no temperatures.
  const std::string whole = kHeader120 + row120(45000000, -0.5, 3.2, 6000, -0.31, 8.7) +
                            row120(45000090, -1.25, 10.5, 6100, -0.9, 9.25) + row120(45000200, -1.5, 11.0, 6200, -1.0, 9.5);
  const std::string cut = without_vesc_columns(whole, {"temp_motor", "temp_mos_max"});
  ASSERT_EQ(cut.find("temp_motor"), std::string::npos) << cut;
  ASSERT_EQ(cut.find("temp_mos_max"), std::string::npos) << cut;
  test::TempFile f_whole("whole.csv", whole), f_cut("vesc.csv", cut);
  AveragedLogRead read_whole, read_cut;
  const auto s_whole = read_averaged_log(f_whole.path(), log_source(f_whole.path()).map, DriveLogLimits{}, &read_whole);
  const auto s_cut = read_averaged_log(f_cut.path(), log_source(f_cut.path()).map, DriveLogLimits{}, &read_cut);
  ASSERT_EQ(s_cut.size(), s_whole.size());
  for (std::size_t k = 0; k < s_cut.size(); ++k) {
    EXPECT_EQ(s_cut[k].t_ns, s_whole[k].t_ns);
    EXPECT_EQ(s_cut[k].i_dq_A, s_whole[k].i_dq_A);
    EXPECT_EQ(s_cut[k].u_dq_V, s_whole[k].u_dq_V);
    EXPECT_EQ(s_cut[k].omega_el_rad_s, s_whole[k].omega_el_rad_s);
    EXPECT_EQ(s_cut[k].u_dc_V, s_whole[k].u_dc_V);
    EXPECT_TRUE(std::isnan(s_cut[k].t_winding_C) && std::isnan(s_cut[k].t_drive_C));
  }
  EXPECT_TRUE(read_whole.layout.t_winding && read_whole.layout.t_drive);
  EXPECT_FALSE(read_cut.layout.t_winding || read_cut.layout.t_drive);
  // The quantities the estimator needs stay required, with the version that added them.
  const std::string msg = vesc_tool_error_of(without_vesc_columns(whole, {"input_voltage"}));
  EXPECT_NE(msg.find("column input_voltage: not in this VESC Tool realtime log"), std::string::npos) << msg;
}

TEST(VescToolLog, ARowAtTheFirmwaresMinus100HasNoWindingReading) {
  // GIVEN temp_motor at −100 on two rows: the value the firmware filters in where it has no reading of the motor's
  // sensor (vedderb/bldc motor/mc_interface.c, update_override_limits), as std::to_string writes it ("-100.000000")
  // WHEN read THEN those samples have no winding temperature, the others theirs, and the summary counts the two.
  test::TempFile f("vesc.csv", kHeader120 + row120_with_motor(45000000, 55.0, -0.5, 3.2, 6000, -0.31, 8.7) +
                                   row120_with_motor(45000100, -100.0, -1.25, 10.5, 6100, -0.9, 9.25) +
                                   row120_with_motor(45000200, 56.5, -1.5, 11.0, 6200, -1.0, 9.5) +
                                   row120_with_motor(45000300, -100.0, -1.5, 11.0, 6200, -1.0, 9.5));
  const LogSource source = log_source(f.path());
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 3U);
  EXPECT_TRUE(read.layout.t_winding);
  EXPECT_TRUE(std::isnan(s[0].t_winding_C));
  EXPECT_DOUBLE_EQ(s[1].t_winding_C, 56.5);
  EXPECT_TRUE(std::isnan(s[2].t_winding_C));
  ASSERT_EQ(read.repairs.no_reading.size(), 1U);
  EXPECT_EQ(read.repairs.no_reading[0].rows, 2U);
  EXPECT_FALSE(read.repairs.no_reading[0].every_row);
  EXPECT_NE(describe(source, read).find("temp_motor (T_winding): 2 rows hold -100 degC, its logger's value for no reading"),
            std::string::npos)
      << describe(source, read);
}

TEST(VescToolLog, ALogAtMinus100OnEveryRowHasNoMotorSensor) {
  // GIVEN a VESC without a motor sensor: temp_motor −100 on every row WHEN read THEN the log has no winding
  // temperature at all (as a log without the column), and the summary says why.
  std::string rows;
  for (long k = 0; k < 4; ++k) rows += row120_with_motor(45000000 + 100 * k, -100.0, -1.0, 10.0, 6000, -0.9, 9.25);
  test::TempFile f("vesc.csv", kHeader120 + rows);
  const LogSource source = log_source(f.path());
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 3U);
  EXPECT_FALSE(read.layout.t_winding);
  for (const auto& x : s) EXPECT_TRUE(std::isnan(x.t_winding_C));
  ASSERT_EQ(read.repairs.no_reading.size(), 1U);
  EXPECT_TRUE(read.repairs.no_reading[0].every_row);
  EXPECT_NE(describe(source, read).find("holds -100 degC, its logger's value for no reading, on every row: no such sensor"),
            std::string::npos)
      << describe(source, read);
}

TEST(VescToolLog, TheMapsNoReadingIsTheFirmwaresAsTheCanDecoderHasIt) {
  // One fact in two forms: the compiled-in map's temp_motor no_reading and can::vesc::kNoMotorReading_C.
  const LogMap map = vesc_tool_log_map();
  const auto c = std::find_if(map.columns.begin(), map.columns.end(),
                              [](const MappedColumn& m) { return m.quantity == Quantity::kTWinding; });
  ASSERT_NE(c, map.columns.end());
  ASSERT_TRUE(c->no_reading.has_value());
  EXPECT_EQ(*c->no_reading, can::vesc::kNoMotorReading_C);
}

TEST(VescToolLog, EachWindowsCountedSpeedIsTheTachometersOverItAndItsNeighbours) {
  // GIVEN four reads at 0, 90, 200 and 290 ms whose tachometer (60° steps, six per electrical turn) reads
  // 1234, 1235, 1235, 1237 WHEN read THEN each window's counted speed is the steps over the centred run of it and
  // the windows beside it, over the run's time (docs/derivations.md §13, "The count's speed at a crawl"): the
  // first window's run starts at the opening read, the last one's ends at the last read.
  test::TempFile f("vesc.csv", kHeader120 + row120(45000000, 0.0, 8.0, 30, 0.0, 0.2, 1234) +
                                   row120(45000090, 0.0, 8.0, 40, 0.0, 0.2, 1235) +
                                   row120(45000200, 0.0, 8.0, 20, 0.0, 0.2, 1235) +
                                   row120(45000290, 0.0, 8.0, 60, 0.0, 0.2, 1237));
  const LogSource source = log_source(f.path());
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{});
  ASSERT_EQ(s.size(), 3U);
  constexpr double kStep = std::numbers::pi / 3.0;
  EXPECT_NEAR(s[0].omega_counted_el_rad_s, 1.0 * kStep / 0.200, 1e-9);  // windows 1–2: 1234 → 1235 in 200 ms
  EXPECT_NEAR(s[1].omega_counted_el_rad_s, 3.0 * kStep / 0.290, 1e-9);  // windows 1–3: 1234 → 1237 in 290 ms
  EXPECT_NEAR(s[2].omega_counted_el_rad_s, 2.0 * kStep / 0.200, 1e-9);  // windows 2–3: 1235 → 1237 in 200 ms
  // The reported speed stays the PLL's rebuilt mean; which one a window stands for is the configuration's.
  EXPECT_NEAR(s[2].omega_el_rad_s, (60.0 + 40.0 * (2000.0 / 30000.0 / 0.090 - 0.5)) * 2.0 * std::numbers::pi / 60.0, 1e-9);
}

// A rotor at 6 000 erpm (628 rad/s electrical: 600 of the tachometer's 60° steps a second) read at `read_ms`: the
// row VESC Tool writes when the reply arrives at `stamp_ms`.
std::string steady_row(long stamp_ms, long read_ms) {
  return row120(stamp_ms, 0.0, 2.0, 6000, 0.0, 2.9, 100000 + read_ms * 3 / 5);
}

/// The samples of a log of `rows` under VESC Tool's current header, and in `read` what reading it did.
std::vector<core::AveragedSample> read_rows(const std::string& rows, AveragedLogRead& read) {
  const test::TempFile f("vesc.csv", kHeader120 + rows);
  return read_averaged_log(f.path(), log_source(f.path()).map, DriveLogLimits{}, &read);
}

TEST(VescToolLog, ARowAfterVescToolAskedAgainAndTheRowAfterItHaveUnknownWindows) {
  // GIVEN rows 90 ms apart but for one 1 020 ms after the row before (VESC Tool gives an unanswered request up
  // after 0.99 s and asks again; the one it gave up on may have been read, the means reset then) and one 980 ms
  // after it WHEN read THEN the window that ends at the late row and the one that starts there are unknown and
  // not used, the next sample says a gap lies before it, and the 980 ms window is a sample.
  test::TempFile f("vesc.csv", kHeader120 + steady_row(0, 0) + steady_row(90, 80) + steady_row(180, 170) +
                                   steady_row(1200, 1190) + steady_row(1290, 1280) + steady_row(1380, 1370) +
                                   steady_row(2360, 2350) + steady_row(2450, 2440));
  const LogSource source = log_source(f.path());
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 5U);
  EXPECT_EQ(read.unknown_windows, 2U);
  EXPECT_EQ(s[1].t_ns, 180'000'000);
  EXPECT_EQ(s[2].t_start_ns, 1'290'000'000);
  EXPECT_TRUE(s[2].gap_before);
  EXPECT_FALSE(s[1].gap_before || s[3].gap_before || s[4].gap_before);
  EXPECT_EQ(s[3].t_start_ns, 1'380'000'000);  // 980 ms: VESC Tool still waited for this reply
  EXPECT_NE(describe(source, read).find("5 averaged samples"), std::string::npos) << describe(source, read);
  EXPECT_NE(describe(source, read).find("2 windows unknown, not used"), std::string::npos) << describe(source, read);
  // Two of eight rows, over a tenth: the key that decides which rows are late replies, with its value and map.
  EXPECT_NE(describe(source, read).find(". Key: request_timeout_s, 0.99 s in builtin:config/log-maps/vesc-tool.yaml"),
            std::string::npos)
      << describe(source, read);
}

TEST(VescToolLog, PolledSlowerThanItsTimeoutARowIsJudgedAgainstTheLogsOwnSpacing) {
  // GIVEN rows 1.005 s apart (VESC Tool polling at 1 Hz, each reply in 5 ms, before the next tick: every
  // spacing over the 0.99 s timeout) but for one 2.01 s after the row before (a request lost: the next left a tick
  // later) WHEN read THEN the 1.005 s windows are samples, and the 2.01 s one and the one after it are unknown:
  // 2.01 s is more than 1.5 times the median spacing.
  AveragedLogRead read;
  const auto s = read_rows(steady_row(0, 0) + steady_row(1005, 1000) + steady_row(2010, 2005) + steady_row(4020, 4015) +
                               steady_row(5025, 5020) + steady_row(6030, 6025) + steady_row(7035, 7030),
                           read);
  ASSERT_EQ(s.size(), 4U);
  EXPECT_EQ(read.unknown_windows, 2U);
  EXPECT_EQ(s[1].t_ns, 2'010'000'000);
  EXPECT_EQ(s[2].t_start_ns, 5'025'000'000);
  EXPECT_TRUE(s[2].gap_before);
  EXPECT_FALSE(s[3].gap_before);
}

TEST(VescToolLog, AStaleReplyArrivingOutOfOrderIsFoundByItsCount) {
  // GIVEN a steady rotor read every 90 ms, and between two rows a reply read 585 ms before it arrives (its request
  // stalled; VESC Tool logs every reply) WHEN read THEN its count is 342 steps behind the row before and 396 behind
  // the row after, each more than the rotor can travel between reads taken after the row before the previous
  // arrived (95 ms at 628 rad/s: 57 steps, 90 ms: 54, and 2 of resolution), and in opposite directions: the two
  // windows beside the stale read are unknown.
  AveragedLogRead read;
  const auto s = read_rows(steady_row(0, 0) + steady_row(90, 80) + steady_row(180, 170) + steady_row(185, -400) +
                               steady_row(270, 260) + steady_row(360, 350),
                           read);
  ASSERT_EQ(s.size(), 3U);
  EXPECT_EQ(read.unknown_windows, 2U);
  EXPECT_EQ(s[1].t_ns, 180'000'000);
  EXPECT_EQ(s[2].t_start_ns, 270'000'000);
  EXPECT_TRUE(s[2].gap_before);
}

TEST(VescToolLog, ACountAheadOfASpeedReadWrongIsNoStaleReply) {
  // GIVEN a Hall drive at a crawl, whose PLL follows the firmware's staircase angle and reads 0 erpm while the count
  // moves 5 steps in one window (more than the speeds read and 2 steps of resolution allow), then 1 WHEN read THEN
  // no window is unknown: one window beyond the bound is a speed read wrong; a stale read puts two beside it, in
  // opposite directions.
  AveragedLogRead read;
  const auto s = read_rows(row120(0, 0.0, 8.0, 0, 0.0, 0.2, 1000) + row120(90, 0.0, 8.0, 0, 0.0, 0.2, 1000) +
                               row120(180, 0.0, 8.0, 0, 0.0, 0.2, 1005) + row120(270, 0.0, 8.0, 0, 0.0, 0.2, 1006) +
                               row120(360, 0.0, 8.0, 0, 0.0, 0.2, 1006),
                           read);
  EXPECT_EQ(s.size(), 4U);
  EXPECT_EQ(read.unknown_windows, 0U);
}

TEST(VescToolLog, RepliesArrivingAfterTheirReadsByAVaryingLatencyAreNotStale) {
  // GIVEN reads 20–40 ms before their rows arrive (a link's latency), so that a window's count over its stamps'
  // spacing is off by up to ±20 ms of travel WHEN read THEN no window is unknown: each read lies after the row
  // before the previous one arrived.
  AveragedLogRead read;
  const auto s = read_rows(steady_row(0, -30) + steady_row(60, 40) + steady_row(170, 130) + steady_row(230, 210) +
                               steady_row(380, 340) + steady_row(420, 400),
                           read);
  EXPECT_EQ(s.size(), 5U);
  EXPECT_EQ(read.unknown_windows, 0U);
}

TEST(VescToolLog, ReadsTheTestBuildHeaderOfVersion120) {
  test::TempFile f("vesc.csv", kHeader120Test + row120test(1000, 0, 1, 100, 0, 0.5) + row120test(1100, 0, 2, 200, 0, 1.0));
  const LogSource source = log_source(f.path());
  EXPECT_NE(source.format.find("1.20 test builds"), std::string::npos) << source.format;
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{});
  ASSERT_EQ(s.size(), 1U);
  EXPECT_DOUBLE_EQ(s[0].u_dq_V[1], 1.0);
}

// VESC Tool 1.17 to 1.19 wrote no d/q voltages: the log reads, its duty cycle kept for the rebuild
// (rotor_frame_rebuild.hpp); a header that lacks a column rpem needs still names the version that added it.
TEST(VescToolLog, AHeaderWithoutDqVoltagesKeepsTheDutyCycleAndAMissingColumnNamesItsVersion) {
  test::TempFile f("vesc.csv", kHeader117 + values22(1000, 40, 50, 0, 1, 100) + "\n" + values22(1100, 40, 50, 0, 1, 200) +
                                   "\n" + values22(1200, 40, 50, 0, 1, 300) + "\n");
  const LogSource source = log_source(f.path());
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), source.map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 2U);
  EXPECT_FALSE(read.layout.u_dq);
  EXPECT_TRUE(read.layout.i_dq && read.layout.duty && read.layout.i_motor && read.layout.u_dc);
  ASSERT_EQ(read.duty.size(), 2U);
  EXPECT_DOUBLE_EQ(read.duty[1], 0.31);                                   // values22's duty_cycle
  EXPECT_DOUBLE_EQ(read.duty_at_start[1], 0.31);                          // the read before
  EXPECT_DOUBLE_EQ(read.u_dc_at_start_V[1], 40.0);                        // its input_voltage
  EXPECT_DOUBLE_EQ(read.i_motor_A[0], 12.5);                              // current_motor
  EXPECT_TRUE(std::isnan(s[0].u_dq_V[0]) && std::isnan(s[0].u_dq_V[1]));  // not in the log: rebuilt by the tools

  std::string header = kHeader117;
  header.replace(header.find("erpm;"), 5, "rpm;");
  const std::string msg = vesc_tool_error_of(header + values22(1000, 40, 50, 0, 1, 100) + "\n");
  EXPECT_NE(msg.find("vesc.csv:1: column erpm: not in this VESC Tool realtime log (a header of no VESC Tool version "
                     "known)"),
            std::string::npos)
      << msg;
  // Every VESC Tool header has erpm: no version to record with (it said "1.17 to 1.19 added it: record the log with
  // VESC Tool 1.20 or later").
  EXPECT_NE(msg.find("; every VESC Tool header has it (since vedderb/vesc_tool 95f18604"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("record the log with"), std::string::npos) << msg;
}

TEST(VescToolLog, TheHeaderlessLogOfVersions111To116IsRefusedWithWhy) {
  // 2323a806 (VESC Tool 1.11, 2019-05-06) wrote the 22 values with no header.
  const std::string msg =
      vesc_tool_error_of(values22(1000, 40, 50, 0, 1, 100) + "\n" + values22(1100, 40, 50, 0, 1, 100) + "\n");
  EXPECT_NE(msg.find("vesc.csv:1: a VESC Tool realtime log without header (VESC Tool 1.11 to 1.16"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("are those VESC Tool 1.17 to 1.19 named (vedderb/vesc_tool 95f18604): put that header line first"),
            std::string::npos)
      << msg;
}

TEST(VescToolLog, MidnightWrapKeepsTimeMonotonic) {
  // 23:59:59.950 → 00:00:00.030: ms_today wraps; the window of the row after midnight is 80 ms.
  test::TempFile f("vesc.csv", kHeader120 + row120(86399870, 0, 1, 100, 0, 1) + row120(86399950, 0, 1, 100, 0, 1) +
                                   row120(30, 0, 1, 100, 0, 1) + row120(120, 0, 1, 100, 0, 1));
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), log_source(f.path()).map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 3U);
  EXPECT_EQ(read.repairs.wraps, 1U);
  EXPECT_EQ(s[1].t_start_ns, 86'399'950'000'000);
  EXPECT_EQ(s[1].t_ns, 86'400'030'000'000);
  EXPECT_EQ(s[2].t_ns, 86'400'120'000'000);
}

TEST(VescToolLog, ALastRowCutOffWhileTheLogWasWrittenIsLeftOutAndSaidSo) {
  // VESC Tool writes a row at a time, newline last: a log copied while logging, or left by an app killed or out of
  // space, ends inside a row. Cut after 60 of its characters (cells missing), just before its closing ';' (every
  // cell there, the last perhaps short) or before its last cell, it is left out and named; the rows before it are read.
  const std::string rows = row120(1000, 0, 1, 100, 0, 1) + row120(1100, 0, 1, 100, 0, 1) + row120(1200, 0, 1, 100, 0, 1);
  const std::string last = row120(1300, 0, 1, 100, 0, 1);
  for (const std::size_t keep : {std::size_t{60}, last.size() - 2, last.size() - 3}) {
    AveragedLogRead read;
    EXPECT_EQ(read_rows(rows + last.substr(0, keep), read).size(), 2U) << keep;
    EXPECT_EQ(read.repairs.cut_line, 5U) << keep;
    EXPECT_NE(describe(read.repairs).find("its last line (5) is a row cut off while the file was written"),
              std::string::npos)
        << describe(read.repairs);
  }
}

TEST(VescToolLog, AWholeLastRowWithoutItsNewlineAndAShortRowInsideAreNoCutRow) {
  // GIVEN the last row whole but for its newline THEN it is read; GIVEN a short row followed by another THEN the
  // file is refused there, as any row of the wrong width is.
  const std::string rows = row120(1000, 0, 1, 100, 0, 1) + row120(1100, 0, 1, 100, 0, 1);
  const std::string last = row120(1200, 0, 1, 100, 0, 1);
  AveragedLogRead read;
  EXPECT_EQ(read_rows(rows + last.substr(0, last.size() - 1), read).size(), 2U);
  EXPECT_EQ(read.repairs.cut_line, 0U);
  const std::string msg = vesc_tool_error_of(kHeader120 + rows + last.substr(0, 60) + "\n" + last);
  EXPECT_NE(msg.find("vesc.csv:4: column *: row has"), std::string::npos) << msg;
}

TEST(VescToolLog, ARowMissingOneValueButClosedByItsSeparatorIsRefusedNotShifted) {
  // GIVEN a row of the 1.20 test builds (32 values, each followed by ';') with d_axis_voltage's cell gone: its
  // 31 values and closing ';' split into as many cells as the header has names. WHEN read THEN it is refused at
  // its line, counting the values it holds (not the empty cell after its last ';') — never read with u_q's value
  // as u_d and gnss_posTime's as u_q. The same counts for a row with one value too many.
  std::string missing = row120test(1100, 0, 1, 100, -0.31, 8.7);
  const std::size_t v_d = missing.find("-0.310000;");
  ASSERT_NE(v_d, std::string::npos);
  missing.erase(v_d, 10);
  const std::string good = row120test(1000, 0, 1, 100, -0.31, 8.7);
  std::string msg = vesc_tool_error_of(kHeader120Test + good + missing + row120test(1200, 0, 1, 100, -0.31, 8.7));
  EXPECT_NE(msg.find("vesc.csv:3: column *: row has 31 cells, header has 32"), std::string::npos) << msg;
  const std::string extra = good.substr(0, good.size() - 1) + "7;\n";
  msg = vesc_tool_error_of(kHeader120Test + good + extra + good);
  EXPECT_NE(msg.find("vesc.csv:3: column *: row has 33 cells, header has 32"), std::string::npos) << msg;
}

TEST(VescToolLog, ADecimalCommaIsRefusedWithItsLikelyCause) {
  // A spreadsheet in a locale with decimal commas saves 40.1 V as "40,1" (';' between cells, as VESC Tool's).
  std::string row = row120(1000, 0, 1, 100, 0, 1);
  row.replace(row.find("40.100000"), 9, "40,100000");
  const std::string msg = vesc_tool_error_of(kHeader120 + row120(900, 0, 1, 100, 0, 1) + row);
  EXPECT_NE(msg.find("vesc.csv:3:2: column input_voltage (u_dc): '40,100000' is not a number (a decimal comma"),
            std::string::npos)
      << msg;
}

TEST(VescToolLog, TwoLogsJoinedIntoOneFileAreRefusedAtTheSecondHeader) {
  const std::string log = kHeader120 + row120(1000, 0, 1, 100, 0, 1) + row120(1100, 0, 1, 100, 0, 1);
  const std::string msg = vesc_tool_error_of(log + log);
  EXPECT_NE(msg.find("vesc.csv:4: column *: the header again (as on line 1): two logs joined into one file?"),
            std::string::npos)
      << msg;
}

TEST(VescToolLog, ALogWithoutItsHeaderLineIsRefusedWithWhy) {
  // Rows of VESC Tool 1.20 and later (55 values) with the header line gone: not a drive log missing its t column.
  const std::string msg = vesc_tool_error_of(row120(1000, 0, 1, 100, 0, 1) + row120(1100, 0, 1, 100, 0, 1));
  EXPECT_NE(msg.find("vesc.csv:1: holds numbers, not column names: the file has no header"), std::string::npos) << msg;
}

TEST(VescToolLog, AStepBackShorterThanHalfADayIsAnErrorNotAWrap) {
  const std::string msg =
      vesc_tool_error_of(kHeader120 + row120(50000000, 0, 1, 100, 0, 1) + row120(49995000, 0, 1, 100, 0, 1));
  EXPECT_NE(msg.find("vesc.csv:3:1: column ms_today (t): time goes back by 5 s (the column wraps every 86400 s"),
            std::string::npos)
      << msg;
}

TEST(VescToolLog, RowsInTheSameMillisecondAreSpreadOverIt) {
  // VESC Tool stamps a reply when it handles it, to the millisecond: three replies handled in one
  // millisecond keep their order inside it.
  test::TempFile f("vesc.csv", kHeader120 + row120(1000, 0, 1, 100, 0, 1) + row120(1020, 0, 1, 100, 0, 1) +
                                   row120(1020, 0, 1, 100, 0, 1) + row120(1020, 0, 1, 100, 0, 1) +
                                   row120(1040, 0, 1, 100, 0, 1));
  AveragedLogRead read;
  const auto s = read_averaged_log(f.path(), log_source(f.path()).map, DriveLogLimits{}, &read);
  ASSERT_EQ(s.size(), 4U);
  EXPECT_EQ(read.repairs.tied_rows, 2U);
  EXPECT_EQ(s[0].t_ns, 1'020'000'000);
  EXPECT_EQ(s[1].t_ns, 1'020'333'333);
  EXPECT_EQ(s[2].t_ns, 1'020'666'667);
  EXPECT_EQ(s[2].t_start_ns, s[1].t_ns);
  EXPECT_EQ(s[3].t_ns, 1'040'000'000);
}

TEST(VescToolLog, ASpeedRebuiltBeyondAnyDrivesIsRefusedAtItsRow) {
  // Each cell within the absolute bound (9e6 erpm = 9.4e5 rad/s < 1e6), but two replies in one millisecond
  // (0.5 ms apart once spread) that differ by all of it give the PLL's speed a slope of 1.9e9 rad/s², which the
  // rebuild's lag term k_p/k_i = 67 ms (docs/derivations.md §13, "Speed at the read") carries to −1.3e8 rad/s. Found by
  // fuzz_log_source (docs/benchmarks.md, "Fuzzing"): the bound holds for the rebuilt speed as for a cell.
  const std::string msg = vesc_tool_error_of(kHeader120 + row120(1000, 0, 1, 9e6, 0, 1) + row120(1020, 0, 1, 9e6, 0, 1) +
                                             row120(1020, 0, 1, 0, 0, 1) + row120(1040, 0, 1, 0, 0, 1));
  EXPECT_NE(msg.find("vesc.csv:4:12: column erpm (omega_el): the window's mean speed rebuilt from the tracker's speeds at "
                     "this read and at line 3 (942478 and 0 rad/s, 0.5 ms apart) is "),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("beyond the plausible ±1e+06 rad/s"), std::string::npos) << msg;
  // A hard acceleration (3 140 rad/s in 20 ms, the rebuild's lag term 8.9e3 rad/s more): within the bound.
  EXPECT_EQ(vesc_tool_error_of(kHeader120 + row120(1000, 0, 1, 100, 0, 1) + row120(1020, 0, 1, 30000, 0, 1) +
                               row120(1040, 0, 1, 30000, 0, 1) + row120(1060, 0, 1, 30000, 0, 1)),
            "");
}

TEST(VescToolLog, ABadCellNamesTheFilesColumnAndTheQuantity) {
  std::string bad = row120(1100, 0, 1, 100, 0, 1);
  bad.replace(bad.find(";1.000000;100"), 9, ";x");  // q_axis_current, the 11th cell
  const std::string msg = vesc_tool_error_of(kHeader120 + row120(1000, 0, 1, 100, 0, 1) + bad);
  EXPECT_NE(msg.find("vesc.csv:3:11: column q_axis_current (i_q): 'x' is not a number"), std::string::npos) << msg;
}

TEST(VescToolLog, OneRowHoldsNoSample) {
  const std::string msg = vesc_tool_error_of(kHeader120 + row120(1000, 0, 1, 100, 0, 1));
  EXPECT_NE(msg.find("vesc.csv:2: no samples: the only row holds means since a read before the log began"),
            std::string::npos)
      << msg;
}

// A logger that writes zeros for the voltages it does not read (one built on a library that keeps no d/q quantities):
// the error names the back EMF the speeds imply at the configured ψm and the largest current, so that a reader sees
// the zeros cannot be the machine's; one voltage in the log, or a machine at rest unexcited, and there is no error.
TEST(AveragedLog, VoltagesZeroInEverySampleOfATurningMachineAreAnError) {
  core::MachineSi machine;
  machine.psi_m_Wb = 5e-3;
  machine.r_s_Ohm = 0.025;
  std::vector<core::AveragedSample> samples(3);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    samples[k].t_ns = static_cast<std::int64_t>(k + 1) * 1'000'000'000;
    samples[k].omega_el_rad_s = -400.0 * static_cast<double>(k);  // 800 rad/s at t = 3 s: 4 V at 5 mWb
    samples[k].i_dq_A = {-3.0, 4.0 * static_cast<double>(k)};     // |i| up to √(9 + 64) A
  }
  std::string msg;
  try {
    check_voltages_recorded(samples, machine, "zeros.csv");
  } catch (const DriveLogError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("zeros.csv: columns u_d, u_q: exactly 0 in every one of the 3 samples"), std::string::npos) << msg;
  EXPECT_NE(msg.find("back EMF of up to 4 V (|omega| x the configured psi_m 0.005 Wb, at t = 3 s)"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("the current reaches 8.544 A"), std::string::npos) << msg;

  samples[1].u_dq_V = {0.0, 0.01};  // one reported voltage: the columns are recorded
  EXPECT_NO_THROW(check_voltages_recorded(samples, machine, "zeros.csv"));
  std::vector<core::AveragedSample> at_rest(4);  // no speed, no current: nothing was there to record
  EXPECT_NO_THROW(check_voltages_recorded(at_rest, machine, "rest.csv"));
  // At rest with current (a few standstill rows): no back EMF to name, but the current's drop across R_s.
  at_rest[2].i_dq_A = {0.0, 2.0};
  msg.clear();
  try {
    check_voltages_recorded(at_rest, machine, "rest.csv");
  } catch (const DriveLogError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("exactly 0 in every one of the 4 samples, while the machine stood still and the current reaches "
                     "2 A, a drop of 0.05 V across the configured r_s 0.025 Ohm: the log carries no voltages"),
            std::string::npos)
      << msg;
  EXPECT_EQ(msg.find("back EMF"), std::string::npos) << msg;
}

TEST(VescToolLog, ACommaSeparatedCopyAndAnUnknownVariantAreReadByName) {
  // VESC Tool's own loader also splits at ','; a third-party logger writing the same names in another
  // order (and without the trailing separator) is read by name.
  std::string comma = kHeader120 + row120(1000, 0, 1, 100, 0, 1) + row120(1100, 0, 2, 100, 0, 2);
  std::replace(comma.begin(), comma.end(), ';', ',');
  test::TempFile f("vesc.csv", comma);
  const auto s = read_averaged_log(f.path(), log_source(f.path()).map, DriveLogLimits{});
  ASSERT_EQ(s.size(), 1U);
  EXPECT_DOUBLE_EQ(s[0].u_dq_V[1], 2.0);

  test::TempFile g("other.csv",
                   "ms_today;erpm;d_axis_current;q_axis_current;d_axis_voltage;q_axis_voltage;input_voltage;temp_motor;"
                   "temp_mos_max\n10;600;0;1;0;0.5;40;30;30\n20;600;0;1;0;0.5;40;30;30\n");
  const LogSource other = log_source(g.path());
  EXPECT_NE(other.format.find("no VESC Tool version known"), std::string::npos) << other.format;
  EXPECT_EQ(read_averaged_log(g.path(), other.map, DriveLogLimits{}).size(), 1U);
}

}  // namespace
}  // namespace rpem::io
