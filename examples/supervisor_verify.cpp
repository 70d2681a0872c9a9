// A supervisory controller that acts only on estimates it can verify (docs/rpemd.md, "Authentication";
// the lines between the markers are quoted there, and test_docs_snippet checks the quote).
//   example_supervisor_verify PUBLISH_KEY_FILE [SECONDS]
#include <chrono>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <span>
#include <string>

#include "rpem/auth/key_file.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/io/exit_codes.hpp"
#include "rpem/schema/decode.hpp"
#include "rpem/supervisor/command_line.hpp"
#include "rpem/supervisor/estimate_gate.hpp"

// [snippet]
struct Supervisor {
  rpem::auth::Keyring keys;  // rpemd's publish key: keys.add(rpem::auth::load_key_file(path))
  // The bytes as received, verified before they are decoded: LCM's typed subscription decodes first, and
  // lcm-gen's decoder throws on a crafted string length, which ends the process.
  void on_estimate(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const std::span bytes(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size);
    if (rpem::auth::verify(keys, channel, bytes) != rpem::auth::Verdict::kVerified) {
      std::printf("ignored: not from rpemd\n");  // forged, altered, unsigned or another key
      return;
    }
    rpem::estimate_t m;
    if (!rpem::schema::decode_exactly(bytes, m)) return;
    if (m.psi_m_valid && m.psi_m_converged)
      std::printf("T_magnet %.1f C (verified)\n", m.t_magnet_C);  // derate: docs/supervisor.md
  }
};
// [snippet]

int main(int argc, char** argv) {
  // SECONDS: how long to run (default: until stopped). Exit codes as example_supervisor's.
  const std::optional<long> seconds = argc > 2 ? rpem::supervisor::parse_seconds(argv[2]) : 1'000'000'000L;
  if (argc < 2 || argc > 3 || !seconds) {
    if (argc > 2) rpem::supervisor::say_seconds_refused(argv[0], argv[2]);
    std::fprintf(stderr, "usage: %s PUBLISH_KEY_FILE [SECONDS]\n", argv[0]);
    return rpem::io::kExitUsage;
  }
  Supervisor supervisor;
  try {
    supervisor.keys.add(rpem::auth::load_key_file(argv[1]));
  } catch (const rpem::auth::KeyError& e) {
    std::fprintf(stderr, "example_supervisor_verify: %s\n", e.what());
    return rpem::io::kExitConfig;
  }
  lcm::LCM lcm;  // LCM's URL: LCM_DEFAULT_URL
  if (!lcm.good()) {
    std::fprintf(stderr, "example_supervisor_verify: LCM is not available (check LCM_DEFAULT_URL)\n");
    return rpem::io::kExitIoError;
  }
  lcm.subscribe("RPEM_ESTIMATE", &Supervisor::on_estimate, &supervisor);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(*seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (lcm.handleTimeout(100) < 0) {
      std::fprintf(stderr, "example_supervisor_verify: LCM stopped receiving\n");
      return rpem::io::kExitIoError;
    }
  }
  return rpem::io::kExitOk;
}
