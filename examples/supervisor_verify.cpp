// A supervisory controller that acts only on estimates it can verify (docs/rpemd.md, "Authentication";
// the lines between the markers are quoted there, and test_docs_snippet checks the quote).
//   example_supervisor_verify PUBLISH_KEY_FILE [SECONDS]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <lcm/lcm-cpp.hpp>
#include <span>
#include <string>

#include "rpem/auth/key_file.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/schema/decode.hpp"
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
    if (m.psi_m_valid) std::printf("T_magnet %.1f C (verified)\n", m.t_magnet_C);  // derate: docs/supervisor.md
  }
};
// [snippet]

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s PUBLISH_KEY_FILE [SECONDS]\n", argv[0]);
    return 64;
  }
  Supervisor supervisor;
  supervisor.keys.add(rpem::auth::load_key_file(argv[1]));
  lcm::LCM lcm;
  lcm.subscribe("RPEM_ESTIMATE", &Supervisor::on_estimate, &supervisor);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(argc > 2 ? std::atoi(argv[2]) : 1000000);
  while (std::chrono::steady_clock::now() < end) lcm.handleTimeout(100);
  return 0;
}
