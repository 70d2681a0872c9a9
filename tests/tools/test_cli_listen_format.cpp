// `rpem listen`'s lines and CSV, printed by generic code from the .lcm files (rpem/schema/text.hpp), read by
// the scripts that read them: the VM suites' checkers (tests/vm/check_daemon_suite.py, imported and run as
// it is; the one-line parsers of check_ax8000_rpemd.py and check_vesc_rpemd.py, quoted). Each message has
// every field set to a value of its own, so a key or a column read from the wrong field shows.
//   - every key check_daemon_suite.py reads from a diagnostics line is the field it means;
//   - every estimate column the checkers read is the field it means, every column a number but `auth`;
//   - a signal_map source's line names its counters in its own terms;
//   - the VESC's stolen reads are found where check_vesc_rpemd.py looks.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "rpem/mirror/diagnostics_t.hpp"
#include "rpem/mirror/estimate_t.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

// One port per test: ctest -j runs the tests of one binary at once, and a listener hears everything on its port
// (the other test's crafted message, or its five estimates, fail this one).
const std::string kUrl = "udpm://239.255.76.67:7819?ttl=0";
const std::string kCraftedUrl = "udpm://239.255.76.67:7820?ttl=0";

std::string source_dir() {
  const char* env = std::getenv("RPEM_SOURCE_DIR");
  return env ? env : std::string(RPEM_TEST_SOURCE_DIR);
}

/// Every numeric field of `m` to a value of its own: the k-th field k + 1000 (integers; booleans and int8
/// fields k), or k + 0.25.
template <class Message>
void fill_distinct(Message& m) {
  int k = 0;
  schema::for_each_field<Message>([&](const auto& f) {
    ++k;
    using T = std::remove_cvref_t<decltype(m.*f.member)>;
    if constexpr (std::is_same_v<T, std::int8_t>) {
      m.*f.member = static_cast<std::int8_t>(k);
    } else if constexpr (std::is_integral_v<T>) {
      m.*f.member = static_cast<T>(k + 1000);
    } else if constexpr (std::is_floating_point_v<T>) {
      m.*f.member = static_cast<T>(k) + static_cast<T>(0.25);
    }
  });
}

TEST(CliListenFormat, TheScriptsThatReadItFindEveryFieldTheyUseUnderItsName) {
  diagnostics_t d{};
  fill_distinct(d);
  d.utime = 1'700'000'000'000'000;
  d.source = "signal_map";
  d.source_name = "vcan0 id 17 map.yaml";  // quoted on the line: its words and numbers are no keys
  estimate_t e{};
  fill_distinct(e);
  e.utime = 1'700'000'000'500'000;
  e.algorithm = "gna";

  test::TempFile out("listen.txt"), csv("est.csv");
  test::ProcessResult heard;
  std::thread listener([&] {
    heard = test::run_command(test::binary_dir() + "/tools/rpem listen --diagnostics --duration 2.5 --lcm-url '" + kUrl +
                              "' --csv " + csv.path());
  });
  {
    lcm::LCM lcm(kUrl);
    ASSERT_TRUE(lcm.good());
    std::this_thread::sleep_for(std::chrono::milliseconds(800));  // the listener subscribes
    for (int i = 0; i < 5; ++i) {
      lcm.publish("RPEM_DIAGNOSTICS", &d);
      lcm.publish("RPEM_ESTIMATE", &e);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  listener.join();
  ASSERT_EQ(heard.exit_code, 0) << heard.output;
  std::ofstream(out.path()) << heard.output;

  const std::string script = R"(
import json, re, sys
sys.path.insert(0, sys.argv[1] + '/tests/vm')
import check_daemon_suite
text = open(sys.argv[2]).read()
out = {'diag': check_daemon_suite.diagnostics(sys.argv[2])[-1], 'est': check_daemon_suite.estimates(sys.argv[3])[-1]}
# check_ax8000_rpemd.py: the last signal_map line
line = re.findall(r'diag \d+ signal_map: (.*)', text)[-1]
out['signal_map'] = {k: int(v) for k, v in re.findall(r'([a-z_]+) (\d+)', line)}
# check_vesc_rpemd.py: the stolen reads
out['stolen'] = max(int(x) for x in re.findall(r'stolen[_ a-z]*[=: ]+(\d+)', text))
print(json.dumps(out))
)";
  test::TempFile script_file("read.py", script);
  const test::ProcessResult parsed =
      test::run_command("python3 " + script_file.path() + " " + source_dir() + " " + out.path() + " " + csv.path());
  ASSERT_EQ(parsed.exit_code, 0) << parsed.output << heard.output;
  const nlohmann::json j = nlohmann::json::parse(parsed.output);

  // check_daemon_suite.py's diagnostics keys (each one it reads).
  const std::map<std::string, std::int64_t> diag{
      {"utime", d.utime},
      {"state", d.state},
      {"overruns", d.overruns},
      {"crc", d.can_crc_error},
      {"dlc", d.can_wrong_dlc},
      {"gaps", d.can_gaps},
      {"lost", d.can_frames_lost},
      {"reopens", d.can_reopens},
      {"publish failures", d.publish_failures},
      {"commands", d.commands_received},
      {"malformed", d.commands_malformed},
      {"rejected", d.commands_rejected},
      {"unauthenticated", d.commands_unauthenticated},
      {"bad mac", d.commands_bad_mac},
      {"replayed", d.commands_replayed},
      {"applied", d.commands_applied},
      {"sequence errors", d.command_sequence_errors},
      {"last seq", d.last_command_seq},
      {"last result", d.last_command_result},
      {"reload requests", d.config_reload_requests},
      {"state file", d.state_file_status},
  };
  for (const auto& [key, value] : diag) {
    ASSERT_TRUE(j["diag"].contains(key)) << key << "\n" << heard.output;
    EXPECT_EQ(j["diag"][key].get<std::int64_t>(), value) << key << "\n" << heard.output;
  }
  // The estimate columns the checkers read (values as %.6g: these have fewer digits).
  const std::map<std::string, double> est{
      {"utime", static_cast<double>(e.utime)},
      {"sample_time_us", static_cast<double>(e.sample_time_us)},
      {"samples", static_cast<double>(e.samples)},
      {"psi_m", e.psi_m_Wb},
      {"r_s", e.r_s_Ohm},
      {"T_magnet", e.t_magnet_C},
      {"T_winding", e.t_winding_C},
      {"frozen", e.frozen},
      {"state", e.state},
  };
  for (const auto& [column, value] : est) {
    ASSERT_TRUE(j["est"].contains(column)) << column;
    EXPECT_EQ(j["est"][column].get<double>(), value) << column;
  }
  EXPECT_EQ(j["est"]["auth"], "unverified");
  // check_ax8000_rpemd.py's signal_map counters, in the source's terms.
  const std::map<std::string, std::int64_t> signal_map{
      {"frames", d.can_frames},
      {"unknown_id", d.can_unknown_id},
      {"wrong_length", d.can_wrong_dlc},
      {"incomplete", d.can_incomplete},
      {"non_finite", d.can_invalid_value},
      {"stale", d.can_stale},
      {"kernel_drops", d.can_kernel_drops},
  };
  const auto signal_map_heard = j["signal_map"].get<std::map<std::string, std::int64_t>>();
  EXPECT_EQ(signal_map_heard, signal_map) << heard.output;
  EXPECT_EQ(j["stolen"].get<std::int64_t>(), d.vesc_stolen_reads);
}

// A message whose string length field is 0 (lcm-gen's decoder throws on it: schema/decode.hpp), sent by anyone
// on the channel: counted and named on stderr, never the end of `rpem listen`; the next message is heard.
TEST(CliListenFormat, AMessageThatDoesNotDecodeIsCountedNotACrash) {
  estimate_t e{};
  e.algorithm = "x";
  std::vector<std::uint8_t> crafted(static_cast<std::size_t>(e.getEncodedSize()));
  ASSERT_EQ(e.encode(crafted.data(), 0, static_cast<int>(crafted.size())), static_cast<int>(crafted.size()));
  const std::vector<std::uint8_t> length_and_text{0, 0, 0, 2, 'x', 0};  // big-endian strlen + 1, then "x\0"
  const auto at = std::search(crafted.begin(), crafted.end(), length_and_text.begin(), length_and_text.end());
  ASSERT_NE(at, crafted.end());
  at[3] = 0;

  test::ProcessResult heard;
  std::thread listener([&] {
    heard = test::run_command(test::binary_dir() + "/tools/rpem listen --duration 2.0 --lcm-url '" + kCraftedUrl + "'");
  });
  {
    lcm::LCM lcm(kCraftedUrl);
    ASSERT_TRUE(lcm.good());
    std::this_thread::sleep_for(std::chrono::milliseconds(800));  // the listener subscribes
    lcm.publish("RPEM_ESTIMATE", crafted.data(), static_cast<unsigned>(crafted.size()));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    lcm.publish("RPEM_ESTIMATE", &e);
  }
  listener.join();
  EXPECT_EQ(heard.exit_code, 0) << heard.output;
  EXPECT_NE(
      heard.output.find("RPEM_ESTIMATE: " + std::to_string(crafted.size()) + " bytes that are not one estimate_t: ignored"),
      std::string::npos)
      << heard.output;
  EXPECT_NE(heard.output.find("1 estimates"), std::string::npos) << heard.output;
  EXPECT_NE(heard.output.find("; 1 malformed"), std::string::npos) << heard.output;
}

}  // namespace
}  // namespace rpem
