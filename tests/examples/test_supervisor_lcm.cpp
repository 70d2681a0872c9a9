// The example supervisory controller (examples/supervisor/main.cpp) end to end over real LCM (loopback
// multicast, ttl 0), as docs/supervisor.md describes it:
//   1. the real rpemd on its simulated drive, signing with its publish key: the supervisor accepts its
//      estimates (verified, fresh, newer) and ignores none;
//   2. rpemd gone, a publisher signing with auth/ under the same key sends a magnet heating up: the
//      supervisor's I_max follows the derating law — 120 A cold, 79.5 A at 110 °C, 34.5 A at 130 °C,
//      nothing at 150 °C (T⁺ = T + 2·4 K; examples/supervisor/supervisor.yaml);
//   3. an eavesdropper who captured those messages off the network sends one altered so that lcm-gen's
//      decoder would throw (a bad MAC: never decoded), then re-sends them: a recent hot one at once (not
//      newer), the cold one (stale) — then, with nothing fresh, the supervisor falls to the floor, 30 A,
//      never back to 120 A.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

#include "rpem/auth/key_file.hpp"
#include "rpem/core/clock.hpp"
#include "signed_estimate.hpp"
#include "support/child_process.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;
const std::string kUrl = "udpm://239.255.76.67:7831?ttl=0";

/// The supervisor's output lines (report.hpp): what, utime, I_max.
struct Line {
  std::string what;
  std::int64_t utime = 0;
  double current_A = 0.0;
};
std::vector<Line> lines_of(const std::string& text) {
  static const std::regex re(R"(^(accepted|ignored \(.*\)|limit.*) (\d+|-): I_max ([0-9.]+) A)");
  std::vector<Line> out;
  std::istringstream in(text);
  for (std::string s; std::getline(in, s);) {
    std::smatch m;
    if (std::regex_search(s, m, re)) out.push_back(Line{m[1], m[2] == "-" ? -1 : std::stoll(m[2]), std::stod(m[3])});
  }
  return out;
}

/// What an eavesdropper on the segment keeps: every RPEM_ESTIMATE's bytes as they went by.
struct Eavesdropper {
  std::vector<std::vector<std::uint8_t>> captured;
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const auto* p = static_cast<const std::uint8_t*>(rbuf->data);
    captured.emplace_back(p, p + rbuf->data_size);
  }
};

TEST(SupervisorLcm, ASecondsArgumentThatIsNoWholePositiveNumberIsAUsageError) {
  // Before 2026-12-04 atoi read "abc", "nan" and "-3" as 0 s (exit 0 at once) and "2.5" as 2 s.
  const std::string program = test::binary_dir() + "/examples/example_supervisor " + RPEM_TEST_SOURCE_DIR +
                              "/examples/supervisor/supervisor.yaml /nonexistent.key ";
  for (const char* bad : {"abc", "nan", "-3", "0", "2.5", "1e3", "99999999999"}) {
    const test::ProcessResult r = test::run_command(program + bad);
    EXPECT_EQ(r.exit_code, 64) << bad << ": " << r.output;
    EXPECT_NE(r.output.find(std::string("SECONDS '") + bad + "' is not a whole number of seconds"), std::string::npos)
        << r.output;
  }
  EXPECT_EQ(test::run_command(program + "5").exit_code, 78);  // read as 5 s: on to the key file, which is missing
}

TEST(SupervisorLcm, TheVerifyExampleSaysWhyItCannotRunAndExits) {
  // It aborted on a missing key file (an uncaught KeyError) and spun at 100 % of a core on an LCM URL it could not
  // open (handleTimeout returning −1 at once).
  const std::string program = test::binary_dir() + "/examples/example_supervisor_verify ";
  const test::ProcessResult seconds = test::run_command(program + "/nonexistent.key 2.5");
  EXPECT_EQ(seconds.exit_code, 64) << seconds.output;
  EXPECT_NE(seconds.output.find("SECONDS '2.5' is not a whole number of seconds"), std::string::npos) << seconds.output;
  const test::ProcessResult missing = test::run_command(program + "/nonexistent.key 5");
  EXPECT_EQ(missing.exit_code, 78) << missing.output;
  EXPECT_NE(missing.output.find("example_supervisor_verify: "), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("/nonexistent.key"), std::string::npos) << missing.output;
  const test::TempFile key("verify.key");
  auth::write_key_file(key.path(), auth::generate_key(3));
  for (const char* program_name : {"example_supervisor_verify ", "example_supervisor "}) {
    const std::string args = std::string(program_name) == "example_supervisor "
                                 ? std::string(RPEM_TEST_SOURCE_DIR) + "/examples/supervisor/supervisor.yaml " + key.path()
                                 : key.path();
    const test::ProcessResult url = test::run_command("LCM_DEFAULT_URL=nosuchprovider://x timeout 20 " + test::binary_dir() +
                                                      "/examples/" + program_name + args + " 5");
    EXPECT_EQ(url.exit_code, 74) << program_name << url.output;
    EXPECT_NE(url.output.find("LCM is not available (check LCM_DEFAULT_URL)"), std::string::npos)
        << program_name << url.output;
  }
}

TEST(SupervisorLcm, DeratesOnVerifiedEstimatesFromRpemdAndTheAuthLibraryAndIgnoresAReplay) {
  const fs::path dir = fs::path(test::TempFile("supervisor").path());
  fs::remove_all(dir);
  fs::create_directories(dir / "credentials");
  fs::create_directories(dir / "state");
  const std::string key_file = (dir / "credentials/publish.key").string();
  auth::write_key_file(key_file, auth::generate_key(2));
  ASSERT_EQ(::setenv("CREDENTIALS_DIRECTORY", (dir / "credentials").c_str(), 1), 0);
  ASSERT_EQ(::setenv("LCM_DEFAULT_URL", kUrl.c_str(), 1), 0);

  test::TempFile log("supervisor.log"), rpemd_log("rpemd.log");
  test::ChildProcess supervisor({test::binary_dir() + "/examples/example_supervisor",
                                 std::string(RPEM_TEST_SOURCE_DIR) + "/examples/supervisor/supervisor.yaml", key_file},
                                log.path());
  ASSERT_GT(supervisor.pid(), 0);

  // 1. rpemd's own estimates.
  test::TempFile config("rpemd.yaml", "daemon:\n  lcm: {url: \"" + kUrl + "\"}\n  state: {file: " +
                                          (dir / "state/estimates.json").string() + "}\n  status_interval_s: 0\n");
  {
    test::ChildProcess rpemd({test::binary_dir() + "/daemon/rpemd", "--config", config.path()}, rpemd_log.path());
    std::this_thread::sleep_for(std::chrono::seconds(3));
    EXPECT_EQ(rpemd.stop(), 0) << test::read_file(rpemd_log.path());
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(800));  // a silence: rpemd's estimates stale
  const std::size_t from_rpemd = lines_of(test::read_file(log.path())).size();

  // 2. A magnet heating up, signed with auth/ under the publish key; 3. the eavesdropper.
  lcm::LCM publisher(kUrl), eavesdropper_lcm(kUrl);
  ASSERT_TRUE(publisher.good() && eavesdropper_lcm.good());
  Eavesdropper eve;
  eavesdropper_lcm.subscribe("RPEM_ESTIMATE", &Eavesdropper::on_message, &eve);
  const auth::Key key = auth::load_key_file(key_file);
  std::vector<std::int64_t> sent_utimes;
  for (const double t_magnet : {60.0, 110.0, 130.0, 150.0}) {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t utime = core::unix_us();
      const auto bytes = test::encode_signed(test::raw_estimate(utime, t_magnet, 60.0), &key);
      ASSERT_EQ(publisher.publish("RPEM_ESTIMATE", bytes.data(), static_cast<unsigned>(bytes.size())), 0);
      sent_utimes.push_back(utime);
      eavesdropper_lcm.handleTimeout(100);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));  // rpemd's 10 Hz
    }
  }
  ASSERT_EQ(eve.captured.size(), sent_utimes.size());
  const auto resend = [&](const std::vector<std::uint8_t>& b) {
    ASSERT_EQ(eavesdropper_lcm.publish("RPEM_ESTIMATE", b.data(), static_cast<unsigned>(b.size())), 0);
  };
  // A crafted message first: a string length of 0, on which lcm-gen's decoder throws — it would end a
  // typed subscriber; the supervisor checks the MAC before it decodes anything.
  std::vector<std::uint8_t> crafted = eve.captured[11];
  const std::size_t length_at = crafted.size() - auth::kTrailerBytes - (6 * 8 + 3) - 4 - 4;  // before "sga\0"
  ASSERT_EQ(crafted[length_at + 3], 4);
  crafted[length_at + 3] = 0;
  resend(crafted);
  resend(eve.captured[10]);  // the second of the 150 °C ones, within the freshness window
  resend(eve.captured[0]);   // the cold magnet, 1.2 s ago
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  resend(eve.captured[0]);  // and again, later still
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(supervisor.stop(), -1);  // killed by SIGTERM: it runs until told

  const std::string out = test::read_file(log.path());
  const std::vector<Line> lines = lines_of(out);
  // 1. rpemd's estimates, about ten a second: all accepted (the limit lines between are the output
  // ageing, or first fresh) — but those rpemd itself marks as held: before its first sample (state starting, if
  // one was published by then) and its estimate as it stops (state stopping, LoopThread::run).
  const std::string not_running = "ignored (not running (rpemd starting, stale or stopping))";
  std::size_t last_estimate = 0, first_accepted = from_rpemd;
  for (std::size_t k = 0; k < from_rpemd; ++k) {
    if (lines[k].what.rfind("limit", 0) != 0) last_estimate = k;
    if (lines[k].what == "accepted") first_accepted = std::min(first_accepted, k);
  }
  EXPECT_EQ(lines[last_estimate].what, not_running) << out;
  int accepted = 0;
  for (std::size_t k = 0; k < from_rpemd; ++k) {
    const bool held = (k < first_accepted || k == last_estimate) && lines[k].what == not_running;
    EXPECT_TRUE(lines[k].what == "accepted" || lines[k].what.rfind("limit", 0) == 0 || held) << lines[k].what << "\n" << out;
    accepted += lines[k].what == "accepted";
  }
  EXPECT_GE(accepted, 15) << out;
  // 2. The law: I_r − (I_r − F)(T⁺ − W)/(L − W) with T⁺ = T + 8 (the message's age adds < 0.001 K).
  std::vector<Line> ours;
  for (std::size_t k = from_rpemd; k < lines.size(); ++k) {
    if (lines[k].what.rfind("limit", 0) != 0) ours.push_back(lines[k]);
  }
  ASSERT_EQ(ours.size(), sent_utimes.size() + 4) << out;
  const double expected_A[] = {120.0, 120.0 - 90.0 * 18.0 / 40.0, 120.0 - 90.0 * 38.0 / 40.0, 0.0};
  for (std::size_t k = 0; k < sent_utimes.size(); ++k) {
    EXPECT_EQ(ours[k].what, "accepted") << out;
    EXPECT_EQ(ours[k].utime, sent_utimes[k]);
    EXPECT_NEAR(ours[k].current_A, expected_A[k / 3], 0.01) << "message " << k << "\n" << out;
  }
  // 3. The crafted message (not decoded: no utime) and the replays: ignored, the supervisor still running,
  // and the limit stays where the newest genuine estimate put it.
  EXPECT_EQ(ours[12].what, "ignored (bad MAC)") << out;
  EXPECT_EQ(ours[12].utime, -1);
  EXPECT_EQ(ours[13].what, "ignored (not newer (replayed or reordered))") << out;
  EXPECT_EQ(ours[13].utime, sent_utimes[10]);
  EXPECT_EQ(ours[13].current_A, 0.0);
  EXPECT_EQ(ours[14].what, "ignored (stale)") << out;
  EXPECT_EQ(ours[14].utime, sent_utimes[0]);
  EXPECT_EQ(ours[14].current_A, 0.0);
  EXPECT_EQ(ours[15].what, "ignored (stale)") << out;
  EXPECT_EQ(ours[15].current_A, 30.0);  // nothing fresh: the floor, not the replayed cold 120 A
  // From the first 150 °C estimate on, I_max is 0 (fresh and too hot) or the 30 A floor (aged out), and
  // the supervisor said when it fell to the floor.
  bool fell_to_floor = false;
  std::size_t first_hot = from_rpemd;
  while (first_hot < lines.size() && !(lines[first_hot].what == "accepted" && lines[first_hot].utime == sent_utimes[9]))
    ++first_hot;
  ASSERT_LT(first_hot, lines.size()) << out;
  for (std::size_t k = first_hot; k < lines.size(); ++k) {
    EXPECT_TRUE(lines[k].current_A == 0.0 || lines[k].current_A == 30.0) << k << "\n" << out;
    fell_to_floor |= lines[k].what == "limit (no fresh estimate)" && lines[k].current_A == 30.0;
  }
  EXPECT_TRUE(fell_to_floor) << out;
  ::unsetenv("CREDENTIALS_DIRECTORY");
  ::unsetenv("LCM_DEFAULT_URL");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rpem
