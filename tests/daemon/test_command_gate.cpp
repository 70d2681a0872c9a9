// RPEM_COMMAND's entry point: admit_command() (decode, admit) and CommandGate (sequence numbers,
// queueing, verdicts, counters, a reload's new policy).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "rpem/command_t.hpp"
#include "rpem/daemon/command_gate.hpp"

namespace rpem::daemon {
namespace {

std::vector<std::uint8_t> encode(std::int64_t seq, std::int8_t command, double psi_m_Wb = 0.0, double r_s_Ohm = 0.0) {
  rpem::command_t m{};
  m.utime = 1;
  m.seq = seq;
  m.command = command;
  m.psi_m_Wb = psi_m_Wb;
  m.r_s_Ohm = r_s_Ohm;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

// These tests are about admission: commands local only, unauthenticated (authenticated ones below).
const CommandPolicy kOn{true, 0.5, 1.7, 1.0, 4.5, CommandAuthentication::kNone};
const auth::Keyring kNoKeys;

TEST(AdmitCommand, EachCommandKindIsAdmitted) {
  struct Case {
    std::int8_t command;
    Command::Kind kind;
  };
  for (const Case& c :
       {Case{rpem::command_t::RESET, Command::Kind::kReset}, Case{rpem::command_t::FREEZE, Command::Kind::kFreeze},
        Case{rpem::command_t::UNFREEZE, Command::Kind::kUnfreeze}}) {
    const CommandVerdict v = admit_command(encode(3, c.command), kOn, kNoKeys, "RPEM_COMMAND", 2);
    EXPECT_TRUE(v.decoded);
    EXPECT_EQ(v.result, CommandResult::kApplied);
    EXPECT_EQ(v.command.kind, c.kind);
    EXPECT_EQ(v.command.seq, 3);
  }
  const CommandVerdict set =
      admit_command(encode(1, rpem::command_t::SET_VALUES, 1.2, 2.5), kOn, kNoKeys, "RPEM_COMMAND", 0);
  EXPECT_EQ(set.result, CommandResult::kApplied);
  EXPECT_EQ(set.command.kind, Command::Kind::kSetValues);
  EXPECT_DOUBLE_EQ(set.command.psi_m_Wb, 1.2);
  EXPECT_DOUBLE_EQ(set.command.r_s_Ohm, 2.5);
}

TEST(AdmitCommand, RefusalsSayWhy) {
  EXPECT_EQ(admit_command(encode(1, rpem::command_t::RESET), CommandPolicy{}, kNoKeys, "RPEM_COMMAND", 0).result,
            CommandResult::kRejectedDisabled);
  EXPECT_EQ(admit_command(encode(5, rpem::command_t::RESET), kOn, kNoKeys, "RPEM_COMMAND", 5).result,
            CommandResult::kRejectedOldSequence);
  EXPECT_EQ(admit_command(encode(0, rpem::command_t::RESET), kOn, kNoKeys, "RPEM_COMMAND", 0).result,
            CommandResult::kRejectedOldSequence);
  EXPECT_EQ(admit_command(encode(-3, rpem::command_t::RESET), kOn, kNoKeys, "RPEM_COMMAND", 0).result,
            CommandResult::kRejectedOldSequence);
  EXPECT_EQ(admit_command(encode(1, 9), kOn, kNoKeys, "RPEM_COMMAND", 0).result, CommandResult::kRejectedUnknown);
  EXPECT_EQ(admit_command(encode(1, 0), kOn, kNoKeys, "RPEM_COMMAND", 0).result, CommandResult::kRejectedUnknown);
  for (const auto& [psi, rs] :
       {std::pair{0.4, 2.0}, {1.8, 2.0}, {1.0, 0.9}, {1.0, 4.6}, {std::nan(""), 2.0}, {1.0, INFINITY}, {-1.0, 2.0}}) {
    const CommandVerdict v = admit_command(encode(1, rpem::command_t::SET_VALUES, psi, rs), kOn, kNoKeys, "RPEM_COMMAND", 0);
    EXPECT_TRUE(v.decoded);
    EXPECT_EQ(v.result, CommandResult::kRejectedBadValues) << psi << " " << rs;
  }
  // D_M's edges are inside.
  EXPECT_EQ(admit_command(encode(1, rpem::command_t::SET_VALUES, 0.5, 4.5), kOn, kNoKeys, "RPEM_COMMAND", 0).result,
            CommandResult::kApplied);
}

TEST(AdmitCommand, AnythingButExactlyOneCommandIsMalformed) {
  const std::vector<std::uint8_t> good = encode(1, rpem::command_t::RESET);
  std::vector<std::uint8_t> truncated(good.begin(), good.end() - 1);
  std::vector<std::uint8_t> trailing(good);
  trailing.push_back(0);
  std::vector<std::uint8_t> other_type(good);
  other_type[0] ^= 1;  // the fingerprint
  const std::uint8_t text[] = "this is not an rpem command_t";
  for (const auto& bytes :
       {truncated, trailing, other_type, std::vector<std::uint8_t>(text, text + sizeof text), std::vector<std::uint8_t>{}}) {
    const CommandVerdict v = admit_command(bytes, kOn, kNoKeys, "RPEM_COMMAND", 0);
    EXPECT_FALSE(v.decoded);
    EXPECT_EQ(v.result, CommandResult::kNone);
  }
}

TEST(CommandGate, QueuesAcceptedCommandsInOrderAndCountsTheRest) {
  auto [to_loop, loop_side] = SpscQueue<Command>::make(2);
  CommandGate gate(kOn, to_loop);
  EXPECT_TRUE(gate.handle(encode(1, rpem::command_t::FREEZE)));
  EXPECT_FALSE(gate.handle(encode(1, rpem::command_t::UNFREEZE)));  // old sequence number
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedOldSequence);
  EXPECT_TRUE(gate.handle(encode(2, rpem::command_t::UNFREEZE)));
  // The queue (capacity 2) is full: busy, and the number is not used up — it may be sent again.
  EXPECT_FALSE(gate.handle(encode(3, rpem::command_t::RESET)));
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedBusy);
  EXPECT_EQ(gate.last_seq(), 3);
  Command c;
  ASSERT_TRUE(loop_side.pop(c));
  EXPECT_EQ(c.seq, 1);
  EXPECT_TRUE(gate.handle(encode(3, rpem::command_t::RESET)));
  EXPECT_EQ(gate.last_result(), CommandResult::kApplied);
  EXPECT_FALSE(gate.handle(std::vector<std::uint8_t>{1, 2, 3}));
  EXPECT_EQ(gate.counters().received, 6);
  EXPECT_EQ(gate.counters().malformed, 1);
  EXPECT_EQ(gate.counters().rejected, 2);
  EXPECT_EQ(gate.last_seq(), 3);  // a malformed message has no verdict
  ASSERT_TRUE(loop_side.pop(c));
  EXPECT_EQ(c.seq, 2);
  ASSERT_TRUE(loop_side.pop(c));
  EXPECT_EQ(c.seq, 3);
  DiagnosticsRows rows;
  gate.report(rows);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_received), 6);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_malformed), 1);
  EXPECT_EQ(rows.get(&diagnostics_t::commands_rejected), 2);
}

// The defect this structure removes: values were checked against the bounds rpemd started with, after
// a reload had changed them. The control thread gives the gate the reloaded policy before the next
// message, and queues the reload before any command checked against it.
TEST(CommandGate, AReloadedPolicyChecksTheVeryNextCommand) {
  auto [to_loop, loop_side] = SpscQueue<Command>::make(8);
  CommandGate gate(kOn, to_loop);
  EXPECT_FALSE(gate.handle(encode(1, rpem::command_t::SET_VALUES, 1.0, 5.0)));
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedBadValues);
  CommandPolicy wider = kOn;
  wider.r_s_max_Ohm = 6.0;
  gate.set_policy(wider);
  EXPECT_TRUE(gate.handle(encode(2, rpem::command_t::SET_VALUES, 1.0, 5.0)));
  gate.set_policy(CommandPolicy{});  // commands disabled by a reload
  EXPECT_FALSE(gate.handle(encode(3, rpem::command_t::RESET)));
  EXPECT_EQ(gate.last_result(), CommandResult::kRejectedDisabled);
}

}  // namespace
}  // namespace rpem::daemon
