// The authenticated supervisory channel end to end, over real LCM (loopback multicast, ttl 0): the real
// rpemd on its simulated drive with a command key and a publish key in its credentials directory,
// `rpem command`, `rpem listen` and `rpem publish-estimate` as a supervisor and an attacker would run
// them. Expected (docs/rpemd.md, "Authentication"):
//   - the keyed command is applied; an unsigned one, one under a key rpemd does not hold, one signed
//     with a guessed key under the right id, a captured one replayed and one with a bit flipped are
//     not, each counted by its reason in RPEM_DIAGNOSTICS;
//   - RPEM_ESTIMATE and RPEM_DIAGNOSTICS verify under the publish key; `rpem listen --key` says
//     "verified" for rpemd's, "FORGED" for an estimate signed with another key, "unverified" unsigned;
//   - after a restart the captured command is still a replay (the sequence number was persisted);
//   - commands enabled without a key, or `authentication: none` with ttl > 0: rpemd exits 78.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>
#include <thread>

#include "rpem/auth/key_file.hpp"
#include "rpem/diagnostics_t.hpp"
#include "rpem/estimate_t.hpp"
#include "support/child_process.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

const std::string kUrl = "udpm://239.255.76.67:7823?ttl=0";
namespace fs = std::filesystem;

struct Heard {
  std::optional<rpem::diagnostics_t> diagnostics;
  int estimates = 0, verified = 0, other = 0;
};

/// Listens for `seconds`; verifies each message under `publish`.
Heard listen(double seconds, const auth::Keyring& publish) {
  lcm::LCM lcm(kUrl);
  Heard h;
  struct Handler {
    Heard& h;
    const auth::Keyring& keys;
    void count(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      const auth::Verdict v =
          auth::verify(keys, channel, std::span(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size));
      (v == auth::Verdict::kVerified ? h.verified : h.other) += 1;
    }
    void estimate(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const rpem::estimate_t*) {
      ++h.estimates;
      count(rbuf, channel);
    }
    void diagnostics(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const rpem::diagnostics_t* m) {
      h.diagnostics = *m;
      count(rbuf, channel);
    }
  } handler{h, publish};
  lcm.subscribe("RPEM_ESTIMATE", &Handler::estimate, &handler);
  lcm.subscribe("RPEM_DIAGNOSTICS", &Handler::diagnostics, &handler);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) lcm.handleTimeout(50);
  return h;
}

std::string rpem_tool() { return test::binary_dir() + "/tools/rpem"; }

test::ProcessResult rpem(const std::string& args) {
  return test::run_command(rpem_tool() + " " + args + " --lcm-url '" + kUrl + "'");
}

TEST(CliAuth, AttacksAreRejectedAndCountedForgedEstimatesFlaggedAndReplayProtectionSurvivesARestart) {
  const fs::path dir = fs::path(test::TempFile("keys").path());
  fs::remove_all(dir);
  fs::create_directories(dir / "credentials");
  fs::create_directories(dir / "attacker");
  fs::create_directories(dir / "state");
  const std::string creds = (dir / "credentials").string();
  auth::write_key_file(creds + "/command.key", auth::generate_key(1));
  auth::write_key_file(creds + "/publish.key", auth::generate_key(2));
  auth::write_key_file((dir / "attacker/guess.key").string(), auth::generate_key(1));    // the right id, not the key
  auth::write_key_file((dir / "attacker/other.key").string(), auth::generate_key(9));    // an id rpemd does not hold
  auth::write_key_file((dir / "attacker/publish.key").string(), auth::generate_key(2));  // forges estimates
  auth::Keyring publish;
  ASSERT_TRUE(publish.add(auth::load_key_file(creds + "/publish.key")));
  const std::string captured = (dir / "attacker/captured.bin").string();

  test::TempFile config("rpemd.yaml", "daemon:\n  lcm: {url: \"" + kUrl +
                                          "\"}\n  commands: {enabled: true}\n  state: {file: " +
                                          (dir / "state/estimates.json").string() + "}\n  status_interval_s: 0\n");
  test::TempFile log("rpemd.log"), log2("rpemd2.log");
  ASSERT_EQ(::setenv("CREDENTIALS_DIRECTORY", creds.c_str(), 1), 0);
  {
    test::ChildProcess rpemd({test::binary_dir() + "/daemon/rpemd", "--config", config.path()}, log.path());
    std::this_thread::sleep_for(std::chrono::seconds(1));
    // The supervisor: one keyed command, captured on the way (as an eavesdropper would).
    EXPECT_EQ(rpem("command --key " + creds + "/command.key --seq 5 freeze --save " + captured).exit_code, 0);
    // The attacker, without the key.
    EXPECT_EQ(rpem("command --seq 100 unfreeze").exit_code, 0);
    EXPECT_EQ(rpem("command --key " + (dir / "attacker/guess.key").string() + " --seq 101 unfreeze").exit_code, 0);
    EXPECT_EQ(rpem("command --key " + (dir / "attacker/other.key").string() + " --seq 102 unfreeze").exit_code, 0);
    EXPECT_EQ(rpem("command --resend " + captured).exit_code, 0);
    EXPECT_EQ(rpem("command --resend " + captured + " --flip-bit 130").exit_code, 0);  // a bit of seq
    // Forged and unsigned estimates, heard by a supervisor running `rpem listen --key`.
    test::ProcessResult listened;
    std::thread listener([&] { listened = rpem("listen --duration 3 --key " + creds + "/publish.key"); });
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    EXPECT_EQ(rpem("publish-estimate --psi-m 0.5 --key " + (dir / "attacker/publish.key").string()).exit_code, 0);
    EXPECT_EQ(rpem("publish-estimate --psi-m 0.5").exit_code, 0);
    listener.join();
    const Heard h = listen(2.5, publish);
    EXPECT_EQ(rpemd.stop(), 0);

    ASSERT_TRUE(h.diagnostics) << test::read_file(log.path());
    const rpem::diagnostics_t& d = *h.diagnostics;
    EXPECT_EQ(d.commands_received, 6);
    EXPECT_EQ(d.commands_applied, 1);
    EXPECT_EQ(d.commands_rejected, 5);
    EXPECT_EQ(d.commands_unauthenticated, 1);
    EXPECT_EQ(d.commands_bad_mac, 2);  // the guessed key, the flipped bit
    EXPECT_EQ(d.commands_unknown_key, 1);
    EXPECT_EQ(d.commands_replayed, 1);
    EXPECT_EQ(d.key_id, 2);
    EXPECT_GT(h.estimates, 15);
    EXPECT_EQ(h.other, 0) << "every message rpemd published verifies under its publish key";
    EXPECT_GT(h.verified, h.estimates);

    EXPECT_NE(listened.output.find("verified"), std::string::npos) << listened.output;
    EXPECT_NE(listened.output.find("psi_m 0.50000 Wb"), std::string::npos) << listened.output;
    EXPECT_NE(listened.output.find("FORGED"), std::string::npos) << listened.output;
    EXPECT_NE(listened.output.find("unverified (unsigned)"), std::string::npos) << listened.output;
    EXPECT_NE(listened.output.find(" 1 FORGED,"), std::string::npos) << listened.output;
    const std::string text = test::read_file(log.path());
    EXPECT_NE(text.find("rejected: bad MAC"), std::string::npos) << text;
    EXPECT_NE(text.find("rejected: unauthenticated"), std::string::npos) << text;
  }
  {
    // Restarted: the captured command is still a replay; a fresh keyed one is applied.
    test::ChildProcess rpemd({test::binary_dir() + "/daemon/rpemd", "--config", config.path()}, log2.path());
    std::this_thread::sleep_for(std::chrono::seconds(1));
    EXPECT_EQ(rpem("command --resend " + captured).exit_code, 0);
    EXPECT_EQ(rpem("command --key " + creds + "/command.key --seq 6 unfreeze").exit_code, 0);
    const Heard h = listen(2.5, publish);
    EXPECT_EQ(rpemd.stop(), 0);
    ASSERT_TRUE(h.diagnostics) << test::read_file(log2.path());
    EXPECT_EQ(h.diagnostics->commands_replayed, 1) << test::read_file(log2.path());
    EXPECT_EQ(h.diagnostics->commands_applied, 1);
    EXPECT_NE(test::read_file(log2.path()).find("last accepted sequence number 5"), std::string::npos)
        << test::read_file(log2.path());
  }
  // Commands enabled and no key: refused at start (78); so is `authentication: none` beyond this host.
  fs::create_directories(dir / "empty");
  ASSERT_EQ(::setenv("CREDENTIALS_DIRECTORY", (dir / "empty").c_str(), 1), 0);
  test::TempFile log3("rpemd3.log");
  test::ChildProcess keyless({test::binary_dir() + "/daemon/rpemd", "--config", config.path()}, log3.path());
  EXPECT_EQ(keyless.wait(), 78);
  EXPECT_NE(test::read_file(log3.path()).find("no command key is configured"), std::string::npos);
  test::TempFile wide(
      "wide.yaml",
      "daemon:\n  lcm: {url: \"udpm://239.255.76.67:7823?ttl=1\"}\n  commands: {enabled: true, authentication: none}\n");
  test::ChildProcess widened({test::binary_dir() + "/daemon/rpemd", "--config", wide.path()}, log3.path());
  EXPECT_EQ(widened.wait(), 78);
  {
    // A reload that enables commands without a key is refused like an invalid file; rpemd keeps running.
    test::TempFile reloadable("reloadable.yaml",
                              "daemon:\n  lcm: {url: \"" + kUrl + "\"}\n  commands: {enabled: false}\n  state: {file: " +
                                  (dir / "state/estimates.json").string() + "}\n  status_interval_s: 0\n");
    test::TempFile log4("rpemd4.log");
    test::ChildProcess rpemd({test::binary_dir() + "/daemon/rpemd", "--config", reloadable.path()}, log4.path());
    std::this_thread::sleep_for(std::chrono::seconds(1));
    std::ofstream(reloadable.path()) << "daemon:\n  lcm: {url: \"" << kUrl
                                     << "\"}\n  commands: {enabled: true}\n  state: {file: "
                                     << (dir / "state/estimates.json").string() << "}\n  status_interval_s: 0\n";
    rpemd.signal(SIGHUP);
    const Heard h = listen(2.5, publish);
    EXPECT_EQ(rpemd.stop(), 0);
    ASSERT_TRUE(h.diagnostics);
    EXPECT_EQ(h.diagnostics->config_reloads_invalid, 1);
    EXPECT_FALSE(h.diagnostics->commands_enabled);
    EXPECT_EQ(h.diagnostics->key_id, 0) << "no publish key: unsigned";
    EXPECT_NE(test::read_file(log4.path()).find("no command key is configured"), std::string::npos);
  }
  ::unsetenv("CREDENTIALS_DIRECTORY");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rpem
