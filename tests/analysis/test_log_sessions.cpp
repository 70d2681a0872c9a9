// A folder's logs joined as one machine's sessions (analysis::load_sessions, `rpem diagnose --log FOLDER`):
// read from files as a user's folder holds them, both logs starting at the same clock time.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/errors.hpp"
#include "support/paper_machine.hpp"
#include "support/temp_file.hpp"

namespace rpem::analysis {
namespace {

/// The layout of the logs below: rotor-frame voltages and currents, the winding temperature if asked.
io::DriveLogLayout dq_layout(bool winding) {
  io::DriveLogLayout layout;
  layout.voltage_abc = layout.current_abc = false;
  layout.voltage_dq = layout.current_dq = true;
  layout.t_winding = winding;
  return layout;
}

/// `rows` rows 2.5 s apart from t = 0, each at the steady operating point (i_d, i_q).
void write_session(const std::string& path, int rows, double i_d_A, double i_q_A, bool winding = false) {
  io::DriveLogWriter writer(path, dq_layout(winding));
  for (int k = 0; k < rows; ++k) {
    io::DriveLogRow r;
    r.sample.t_ns = static_cast<std::int64_t>(k) * 2'500'000'000LL;
    r.sample.voltage_frame = r.sample.current_frame = core::Frame::kDq;
    r.sample.omega_el_rad_s = 300.0;
    r.sample.u_dc_V = 400.0;
    r.sample.i_A = core::Vec3(i_d_A, i_q_A, 0.0);
    r.sample.u_V = core::Vec3(10.0, 200.0, 0.0);
    if (winding) r.sample.t_winding_C = 40.0;
    writer.write(r);
  }
  writer.flush();
}

TEST(LogSessions, JoinedOneAfterAnotherEachStartingAfresh) {
  const test::TempFile a("a.csv"), b("b.csv");
  // Two operating points 2.6 times apart in current: rows at the boundary would be in transition in one log.
  write_session(a.path(), 400, -3.0, 4.0);
  write_session(b.path(), 400, -8.0, 10.0);
  const LogData log = load_sessions("rides", {a.path(), b.path()}, test::paper_machine_si(), {});

  EXPECT_EQ(log.path, "rides");
  ASSERT_EQ(log.sessions(), 2U);
  EXPECT_EQ(log.session_first, (std::vector<std::size_t>{0, 400}));
  EXPECT_EQ(log.session_logs, (std::vector<std::string>{a.path(), b.path()}));
  EXPECT_EQ(log.session_end(0), 400U);
  EXPECT_EQ(log.session_end(1), 800U);
  EXPECT_TRUE(log.starts_session(400));
  EXPECT_FALSE(log.starts_session(0));
  EXPECT_FALSE(log.starts_session(401));

  // Both clocks start at 0: the second session follows the first's last row (399 × 2.5 s) after 1 s.
  EXPECT_NEAR(log.t_s(400), 399 * 2.5 + 1.0, 1e-9);
  EXPECT_NEAR(log.t_s(799), 399 * 2.5 + 1.0 + 399 * 2.5, 1e-9);
  EXPECT_TRUE(log.samples.gap_before(400));
  EXPECT_FALSE(log.samples.gap_before(399));
  EXPECT_FALSE(log.samples.gap_before(0));

  // The boundary is no interval of the log's, no pause, and no neighbour of either row.
  EXPECT_DOUBLE_EQ(log.median_dt_s, 2.5);
  EXPECT_EQ(log.pauses, 0U);
  EXPECT_EQ(log.mode, ModelMode::kSteadyState);
  EXPECT_EQ(log.excluded_transitional, 0U);
  // Sampled time: 399 + 399 intervals, the boundary none, so rows 399 and 400 both lie at 399 of 798 intervals,
  // the boundary of blocks 19 and 20.
  ASSERT_EQ(log.blocks, 40);
  EXPECT_EQ(log.block(398), 19);
  EXPECT_EQ(log.block(399), 20);
  EXPECT_EQ(log.block(400), 20);
  EXPECT_EQ(log.block(799), 39);
}

TEST(LogSessions, OneLogIsOneSession) {
  const test::TempFile a("a.csv");
  write_session(a.path(), 100, -3.0, 4.0);
  const LogData log = load_log(a.path(), test::paper_machine_si(), {});
  EXPECT_EQ(log.sessions(), 1U);
  EXPECT_EQ(log.session_logs, (std::vector<std::string>{a.path()}));
  EXPECT_EQ(log.session_end(0), 100U);
  for (std::size_t k = 0; k < log.size(); ++k) EXPECT_FALSE(log.starts_session(k)) << k;
  EXPECT_NEAR(log.t_s(99), 99 * 2.5, 1e-9);
}

TEST(LogSessions, LogsOfDifferentColumnsAreRefusedNamingTheOneThatDiffers) {
  const test::TempFile a("a.csv"), b("b.csv");
  write_session(a.path(), 100, -3.0, 4.0);
  write_session(b.path(), 100, -3.0, 4.0, true);
  try {
    (void)load_sessions("rides", {a.path(), b.path()}, test::paper_machine_si(), {});
    FAIL() << "joined logs of different columns";
  } catch (const io::DriveLogError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), b.path());
    EXPECT_NE(what.find("t_winding (here, not there)"), std::string::npos) << what;
    EXPECT_NE(what.find(a.path()), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace rpem::analysis
