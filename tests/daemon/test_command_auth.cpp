// Authenticated RPEM_COMMAND (docs/rpemd.md, "Authentication"): the gate refuses each kind of attack
// for its own reason and counts it; replay protection survives a restart through the persisted
// sequence number; keys come from the credentials directory; the configuration refuses
// `authentication: none` where LCM reaches the network.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <vector>

#include "rpem/auth/key_file.hpp"
#include "rpem/command_t.hpp"
#include "rpem/daemon/command_gate.hpp"
#include "rpem/daemon/credentials.hpp"
#include "rpem/daemon/state_file.hpp"
#include "rpem/io/errors.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

const CommandPolicy kRequired{true, 0.5, 1.7, 1.0, 4.5, CommandAuthentication::kRequired};

auth::Key key(std::int32_t id, std::uint8_t fill) {
  std::array<std::uint8_t, auth::kKeyBytes> bytes{};
  bytes.fill(fill);
  return {id, bytes};
}

/// rpemd's copy of a key (the supervisor signs with its own, key(id, fill)).
CommandKeys held(std::int32_t id, std::uint8_t fill) {
  CommandKeys keys;
  EXPECT_TRUE(keys.keys.add(key(id, fill)));
  return keys;
}

std::vector<std::uint8_t> command(std::int64_t seq, const auth::Key* signer, std::int32_t key_id = -1,
                                  const std::string& channel = "RPEM_COMMAND") {
  rpem::command_t m{};
  m.utime = 1;
  m.seq = seq;
  m.command = rpem::command_t::SET_VALUES;
  m.psi_m_Wb = 1.1;
  m.r_s_Ohm = 2.2;
  m.key_id = key_id >= 0 ? key_id : signer != nullptr ? signer->id() : 0;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  if (signer != nullptr) {
    EXPECT_TRUE(auth::sign(*signer, channel, bytes));
  }
  return bytes;
}

// LCM's C++ encoding of the test vector's message is LCM's Python encoding of it (tests/auth/test_mac.cpp,
// tests/auth/make_test_vector.py), and the MAC sits in its last 32 bytes.
TEST(CommandAuth, CppEncodingIsTheVectorsAndEndsWithTheMac) {
  rpem::command_t m{};
  m.utime = 1700000000000000;
  m.seq = 42;
  m.command = 4;
  m.psi_m_Wb = 1.05;
  m.r_s_Ohm = 2.4;
  m.key_id = 7;
  for (auto& b : m.mac) b = 0xAB;
  std::vector<std::uint8_t> e(static_cast<std::size_t>(m.getEncodedSize()));
  ASSERT_EQ(m.encode(e.data(), 0, static_cast<int>(e.size())), static_cast<int>(e.size()));
  const std::string hex = "1508b5fe54b54dd200060a24181e4000000000000000002a043ff0cccccccccccd400333333333333300000007";
  char buf[3];
  std::string got;
  for (std::size_t k = 0; k + auth::kMacBytes < e.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%02x", e[k]);
    got += buf;
  }
  EXPECT_EQ(got, hex);
  for (std::size_t k = e.size() - auth::kMacBytes; k < e.size(); ++k) EXPECT_EQ(e[k], 0xAB);
}

TEST(CommandAuth, TheGateRefusesEachAttackForItsReasonAndCountsIt) {
  const auth::Key k1 = key(1, 0x11), stranger = key(1, 0x99), k9 = key(9, 0x11);
  auto [to_loop, loop_side] = SpscQueue<Command>::make(16);
  CommandGate gate(kRequired, to_loop, held(1, 0x11));
  const std::vector<std::uint8_t> valid = command(5, &k1);
  EXPECT_TRUE(gate.handle(valid));
  EXPECT_FALSE(gate.handle(command(6, nullptr)));  // well-formed, unsigned
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedUnauthenticated);
  EXPECT_FALSE(gate.handle(command(7, &k9)));  // a key rpemd does not hold
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedUnknownKey);
  EXPECT_FALSE(gate.handle(command(8, &stranger)));  // guesses the key id, not the key
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedBadMac);
  EXPECT_FALSE(gate.handle(command(9, &k1, -1, "RPEM_ESTIMATE")));  // signed for another channel
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedBadMac);
  std::vector<std::uint8_t> flipped = command(10, &k1);
  flipped[20] ^= 0x04;  // one bit of seq
  EXPECT_FALSE(gate.handle(flipped));
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedBadMac);
  EXPECT_FALSE(gate.handle(valid));  // captured and replayed
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedOldSequence);
  EXPECT_FALSE(gate.handle(std::vector<std::uint8_t>{1, 2, 3}));
  const CommandGate::Counters& c = gate.counters();
  EXPECT_EQ(c.received, 8);
  EXPECT_EQ(c.malformed, 1);
  EXPECT_EQ(c.rejected, 6);
  EXPECT_EQ(c.unauthenticated, 1);
  EXPECT_EQ(c.unknown_key, 1);
  EXPECT_EQ(c.bad_mac, 3);
  EXPECT_EQ(c.replayed, 1);
  DiagnosticsRows rows;
  gate.report(rows);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_bad_mac), 3);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_unknown_key), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_unauthenticated), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_replayed), 1);
  EXPECT_EQ(to_loop.size(), 1u);  // only the valid one
}

TEST(CommandAuth, AuthenticationNoneAdmitsUnsignedCommands) {
  auto [to_loop, loop_side] = SpscQueue<Command>::make(4);
  CommandPolicy none = kRequired;
  none.authentication = CommandAuthentication::kNone;
  CommandGate gate(none, to_loop);
  EXPECT_TRUE(gate.handle(command(1, nullptr)));
}

struct FileStore : SequenceStore {
  std::string path;
  bool store(std::int64_t seq) noexcept override { return write_command_sequence(path, seq).empty(); }
};

TEST(CommandAuth, AReplayIsRejectedAfterARestart) {
  test::TempFile state("estimates.json");
  FileStore store;
  store.path = command_sequence_file(state.path());
  std::filesystem::remove(store.path);
  const auth::Key k1 = key(1, 0x11);
  const std::vector<std::uint8_t> valid = command(41, &k1);
  {
    auto [to_loop, loop_side] = SpscQueue<Command>::make(4);
    CommandGate gate(kRequired, to_loop, held(1, 0x11), load_command_sequence(store.path), &store);
    EXPECT_TRUE(gate.handle(valid));
  }
  EXPECT_EQ(load_command_sequence(store.path), 41);
  auto [to_loop, loop_side] = SpscQueue<Command>::make(4);
  CommandGate restarted(kRequired, to_loop, held(1, 0x11), load_command_sequence(store.path), &store);
  EXPECT_FALSE(restarted.handle(valid));
  EXPECT_EQ(restarted.last_result(), CommandResult::kRejectedOldSequence);
  EXPECT_TRUE(restarted.handle(command(42, &k1)));
  std::filesystem::remove(store.path);
}

TEST(CommandAuth, AnUnpersistableSequenceNumberIsNotAccepted) {
  struct Failing : SequenceStore {
    bool store(std::int64_t) noexcept override { return false; }
  } failing;
  const auth::Key k1 = key(1, 0x11);
  auto [to_loop, loop_side] = SpscQueue<Command>::make(4);
  CommandGate gate(kRequired, to_loop, held(1, 0x11), 0, &failing);
  EXPECT_FALSE(gate.handle(command(1, &k1)));
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedNotPersisted);
  EXPECT_EQ(to_loop.size(), 0u);
}

TEST(CommandAuth, ACorruptSequenceFileIsAnErrorNotAFreshStart) {
  test::TempFile f("commands.json", "{\"format\": \"rpemd-commands-1\", \"last_accepted_seq\": \"x\"}");
  EXPECT_THROW((void)load_command_sequence(f.path()), std::runtime_error);
  EXPECT_EQ(load_command_sequence(f.path() + ".none"), 0);
}

TEST(CommandAuth, KeysComeFromTheCredentialsDirectory) {
  const std::filesystem::path dir = std::filesystem::path(test::TempFile("creds").path());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  auto put = [&](const std::string& name, const auth::Key& k) { auth::write_key_file((dir / name).string(), k); };
  put("rpem_command.key", key(1, 1));
  put("rpem_command-next.key", key(2, 2));
  put("rpem_publish.key", key(5, 5));
  put("unrelated", key(6, 6));
  DaemonKeys keys = load_credential_keys(dir.c_str());
  EXPECT_EQ(keys.command.size(), 2);
  EXPECT_NE(keys.command.find(1), nullptr);
  EXPECT_NE(keys.command.find(2), nullptr);
  ASSERT_TRUE(keys.publish.has_value());
  EXPECT_EQ(keys.publish->id(), 5);
  put("rpem_command-third.key", key(3, 3));
  EXPECT_THROW((void)load_credential_keys(dir.c_str()), auth::KeyError);
  std::filesystem::remove(dir / "rpem_command-third.key");
  ::chmod((dir / "rpem_publish.key").c_str(), 0644);
  EXPECT_THROW((void)load_credential_keys(dir.c_str()), auth::KeyError);
  EXPECT_TRUE(load_credential_keys(nullptr).command.empty());
  std::filesystem::remove_all(dir);
}

TEST(CommandAuth, CommandsEnabledNeedAKeyUnlessExplicitlyLocalOnly) {
  LiveConfig live;
  live.commands_enabled = true;
  EXPECT_NE(command_key_problem(live, auth::Keyring{}), "");
  auth::Keyring one;
  ASSERT_TRUE(one.add(key(1, 1)));
  EXPECT_EQ(command_key_problem(live, one), "");
  live.command_authentication = CommandAuthentication::kNone;
  EXPECT_EQ(command_key_problem(live, auth::Keyring{}), "");
  live.commands_enabled = false;
  live.command_authentication = CommandAuthentication::kRequired;
  EXPECT_EQ(command_key_problem(live, auth::Keyring{}), "");
}

TEST(CommandAuth, AuthenticationNoneIsRefusedWhereLcmReachesTheNetwork) {
  EXPECT_TRUE(lcm_is_local("udpm://239.255.76.67:7667?ttl=0"));
  EXPECT_TRUE(lcm_is_local("udpm://239.255.76.67:7667"));
  EXPECT_TRUE(lcm_is_local("udpm://239.255.76.67:7667?recv_buf_size=100000&ttl=0"));
  EXPECT_TRUE(lcm_is_local("memq://"));
  EXPECT_FALSE(lcm_is_local("udpm://239.255.76.67:7667?ttl=1"));
  EXPECT_FALSE(lcm_is_local("tcpq://192.168.1.2:7700"));
  for (const char* ttl : {"1", "32"}) {
    test::TempFile f("rpemd.yaml", std::string("daemon:\n  lcm: {url: \"udpm://239.255.76.67:7667?ttl=") + ttl +
                                       "\"}\n  commands: {enabled: true, authentication: none}\n");
    try {
      (void)load_daemon_config(f.path());
      ADD_FAILURE() << "accepted authentication: none with ttl " << ttl;
    } catch (const io::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("authentication"), std::string::npos) << e.what();
    }
  }
  test::TempFile local(
      "rpemd.yaml",
      "daemon:\n  lcm: {url: \"udpm://239.255.76.67:7667?ttl=0\"}\n  commands: {enabled: true, authentication: none}\n");
  EXPECT_EQ(load_daemon_config(local.path()).live.command_authentication, CommandAuthentication::kNone);
}

}  // namespace
}  // namespace rpem::daemon
