// libFuzzer target for rpemd's RPEM_COMMAND entry point (daemon/src/command_gate.cpp). The input is
//   [flags][last accepted sequence number: 8 bytes, little endian][message]…, each message [length][bytes]
// flags: bit 0 commands enabled, bit 1 a narrow D_M, bits 2–7 which messages the loop pops after.
// First the pure step: admit_command() on every message against the header's policy and number; then
// the stateful gate over the whole sequence into a small queue. It must never crash and:
//   - a verdict exists exactly for what decodes, and decoding is exact: the bytes re-encode to themselves;
//   - an admitted command is enabled, newer than the last accepted one, a known kind with its fields,
//     values finite and inside D_M; a refusal names the first check that failed;
//   - the gate queues commands in strictly increasing sequence order, never more than it admits, and
//     its counters add up: received = malformed + rejected + queued.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "rpem/command_t.hpp"
#include "rpem/daemon/command_gate.hpp"

namespace {

using rpem::daemon::Command;
using rpem::daemon::CommandPolicy;
using rpem::daemon::CommandResult;
using rpem::daemon::CommandVerdict;

void require(bool ok) {
  if (!ok) std::abort();
}

bool inside(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

void check_verdict(std::span<const std::uint8_t> bytes, const CommandPolicy& p, std::int64_t last, const CommandVerdict& v) {
  rpem::command_t m;
  const bool exact = m.decode(bytes.data(), 0, static_cast<int>(bytes.size())) == static_cast<int>(bytes.size());
  require(v.decoded == exact);
  if (!v.decoded) {
    require(v.result == CommandResult::kNone);
    return;
  }
  std::array<std::uint8_t, 256> again{};  // a message is at most 255 bytes (its length byte)
  require(m.encode(again.data(), 0, static_cast<int>(bytes.size())) == static_cast<int>(bytes.size()));
  require(std::memcmp(again.data(), bytes.data(), bytes.size()) == 0);
  require(v.command.seq == m.seq);
  const bool known = m.command >= rpem::command_t::RESET && m.command <= rpem::command_t::SET_VALUES;
  const bool values = inside(m.psi_m_Wb, p.psi_m_min_Wb, p.psi_m_max_Wb) && inside(m.r_s_Ohm, p.r_s_min_Ohm, p.r_s_max_Ohm);
  CommandResult expected = CommandResult::kApplied;
  if (!p.enabled) {
    expected = CommandResult::kRejectedDisabled;
  } else if (m.seq <= last) {
    expected = CommandResult::kRejectedOldSequence;
  } else if (!known) {
    expected = CommandResult::kRejectedUnknown;
  } else if (m.command == rpem::command_t::SET_VALUES && !values) {
    expected = CommandResult::kRejectedBadValues;
  }
  require(v.result == expected);
  if (v.result != CommandResult::kApplied) return;
  const Command::Kind kinds[] = {Command::Kind::kReset, Command::Kind::kFreeze, Command::Kind::kUnfreeze,
                                 Command::Kind::kSetValues};
  require(v.command.kind == kinds[m.command - 1]);
  if (v.command.kind == Command::Kind::kSetValues) {
    require(inside(v.command.psi_m_Wb, p.psi_m_min_Wb, p.psi_m_max_Wb));
    require(inside(v.command.r_s_Ohm, p.r_s_min_Ohm, p.r_s_max_Ohm));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 9) return 0;
  const std::uint8_t flags = data[0];
  CommandPolicy policy{(flags & 1) != 0, 0.5, 1.7, 1.0, 4.5};
  if (flags & 2) policy = {(flags & 1) != 0, 1.0, 1.2, 2.0, 2.5};
  std::int64_t last = 0;
  std::memcpy(&last, data + 1, sizeof last);
  std::vector<std::span<const std::uint8_t>> messages;
  for (std::size_t at = 9; at < size;) {
    const std::size_t n = std::min<std::size_t>(data[at], size - at - 1);
    messages.emplace_back(data + at + 1, n);
    at += 1 + n;
  }

  for (const auto& message : messages) check_verdict(message, policy, last, rpem::daemon::admit_command(message, policy, last));

  rpem::daemon::SpscQueue<Command> to_loop(4);
  rpem::daemon::CommandGate gate(policy, to_loop);
  std::int64_t queued = 0, previous = INT64_MIN;
  Command c;
  auto pop = [&] {
    while (to_loop.pop(c)) {
      require(c.seq > previous);
      previous = c.seq;
    }
  };
  for (std::size_t k = 0; k < messages.size(); ++k) {
    queued += gate.handle(messages[k]);
    if ((flags >> (2 + k % 6)) & 1) pop();
  }
  pop();
  const auto& n = gate.counters();
  require(n.received == static_cast<std::int64_t>(messages.size()));
  require(n.received == n.malformed + n.rejected + queued);
  return 0;
}
