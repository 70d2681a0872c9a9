// A supervisory controller that derates the drive's current on the magnet's and the winding's
// temperatures from rpemd's estimates — only verified, fresh and newer ones (docs/supervisor.md; the lines
// between the markers are quoted there, and test_docs_supervisor_md_snippet checks the quote).
//   example_supervisor CONFIG PUBLISH_KEY_FILE [SECONDS]
// LCM's URL: LCM_DEFAULT_URL (LCM's own variable). Prints a line at start, per estimate, and between
// estimates when the last one ages out or I_max moves by 0.1 A (report.hpp).
// Exit codes: 64 usage, 78 configuration or key, 74 no LCM.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <string>

#include "rpem/auth/key_file.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/exit_codes.hpp"
#include "rpem/supervisor/command_line.hpp"
#include "rpem/supervisor/config.hpp"
#include "rpem/supervisor/report.hpp"
#include "rpem/supervisor/supervisor.hpp"

// [snippet]
struct Handler {
  rpem::supervisor::Supervisor& supervisor;
  // The bytes as received (not LCM's typed subscription: nothing is decoded before the MAC verifies)
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const std::span bytes(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size);
    // verified, fresh by the supervisor's clock at receipt, newer than the last accepted: else ignored
    const auto received = supervisor.on_message(channel, bytes, rbuf->recv_utime);
    const auto limit = supervisor.current_limit(rpem::core::unix_us());  // I_max: to the drive
    std::printf("%s\n", rpem::supervisor::verdict_line(received, limit).c_str());
  }
};
// [snippet]

int main(int argc, char** argv) {
  using namespace rpem;
  // SECONDS: how long to run (default: a billion, i.e. until stopped).
  const std::optional<long> seconds = argc > 3 ? supervisor::parse_seconds(argv[3]) : 1'000'000'000L;
  if (argc < 3 || argc > 4 || !seconds) {
    if (argc > 3) rpem::supervisor::say_seconds_refused(argv[0], argv[3]);
    std::fprintf(stderr, "usage: %s CONFIG PUBLISH_KEY_FILE [SECONDS]\n", argv[0]);
    return io::kExitUsage;
  }
  auth::Keyring keys;
  supervisor::Config config;
  try {
    config = supervisor::load_config(argv[1]);
    keys.add(auth::load_key_file(argv[2]));
  } catch (const io::ConfigError& e) {
    std::fprintf(stderr, "example_supervisor: %s\n", e.what());
    return io::kExitConfig;
  } catch (const auth::KeyError& e) {
    std::fprintf(stderr, "example_supervisor: %s\n", e.what());
    return io::kExitConfig;
  }
  supervisor::Supervisor supervisor(config, std::move(keys));
  lcm::LCM lcm;
  if (!lcm.good()) {
    std::fprintf(stderr, "example_supervisor: LCM is not available (check LCM_DEFAULT_URL)\n");
    return io::kExitIoError;
  }
  Handler handler{supervisor};
  lcm.subscribe("RPEM_ESTIMATE", &Handler::on_message, &handler);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(*seconds);
  // Between messages: a line when the estimate ages out, or I_max moves by 0.1 A (held values heating).
  supervisor::CurrentLimit printed = supervisor.current_limit(core::unix_us());
  std::printf("%s\n", supervisor::limit_line(core::unix_us(), printed).c_str());
  while (std::chrono::steady_clock::now() < end) {
    const int handled_count = lcm.handleTimeout(100);
    if (handled_count < 0) {
      std::fprintf(stderr, "example_supervisor: LCM stopped receiving\n");
      return io::kExitIoError;
    }
    const bool handled = handled_count > 0;
    const supervisor::CurrentLimit limit = supervisor.current_limit(core::unix_us());
    const bool moved = limit.fresh != printed.fresh || std::abs(limit.current_A - printed.current_A) >= 0.1;
    if (!handled && moved) std::printf("%s\n", supervisor::limit_line(core::unix_us(), limit).c_str());
    if (handled || moved) printed = limit;
  }
  return io::kExitOk;
}
