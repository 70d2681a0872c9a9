// libFuzzer target for rpemd's authenticated RPEM_COMMAND entry point (daemon/src/command_gate.cpp). The
// input is
//   [flags][auth][last accepted sequence number: 8 bytes, little endian][message]…, each [length][bytes]
// flags: bit 0 commands enabled, bit 1 a narrow D_M, bits 2–7 which messages the loop pops after.
// auth:  bit 0 authentication required; bits 1–2 how the harness signs each message long enough to
//        hold the trailer before it is checked — 0 not at all (the bytes as they are), 1 with key 1 and
//        2 with key 2 (both held: a rotation), 3 with key 9 (not held); bit 3 signs for RPEM_ESTIMATE
//        instead of RPEM_COMMAND (a valid MAC for another channel).
// So the fuzzer reaches every step after authentication with correctly signed mutations, and every
// refusal of authentication with forged ones. First the pure step: admit_command() on every message;
// then the stateful gate over the whole sequence into a small queue. It must never crash and:
//   - a verdict exists exactly for what decodes, and decoding is exact: the bytes re-encode to themselves;
//   - authentication: key id 0 unauthenticated, a key not held unknown, anything but the harness's own
//     correct signature a bad MAC — a forgery is never admitted;
//   - an admitted command is enabled, authentic (if required), newer than the last accepted one, a known
//     kind with its fields, values finite and inside D_M; a refusal names the first check that failed;
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

#include "rpem/auth/mac.hpp"
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

constexpr std::string_view kChannel = "RPEM_COMMAND";

rpem::auth::Key key(std::int32_t id) {
  std::array<std::uint8_t, rpem::auth::kKeyBytes> bytes{};
  bytes.fill(static_cast<std::uint8_t>(0x30 + id));
  return {id, bytes};
}

/// The keys rpemd holds (1 and 2: a rotation).
rpem::auth::Keyring held_keys() {
  rpem::auth::Keyring held;
  held.add(key(1));
  held.add(key(2));
  return held;
}

struct Harness {
  rpem::auth::Keyring held = held_keys();
  std::array<rpem::auth::Key, 3> signers{key(1), key(2), key(9)};  // the harness's own: two held, one not
  int sign_mode = 0;                                               // 0 none, 1 key 1, 2 key 2, 3 key 9
  bool other_channel = false;
  /// Whether the harness signed `bytes` correctly for RPEM_COMMAND under a held key.
  [[nodiscard]] bool authentic() const { return (sign_mode == 1 || sign_mode == 2) && !other_channel; }
};

/// The message as checked, signed in place (in the harness's copy of the input) as the header says.
std::span<const std::uint8_t> prepare(std::span<std::uint8_t> m, const Harness& h) {
  if (h.sign_mode != 0 && m.size() >= rpem::auth::kTrailerBytes) {
    const std::int32_t id = h.sign_mode == 3 ? 9 : h.sign_mode;
    std::uint8_t* p = m.data() + m.size() - rpem::auth::kTrailerBytes;
    p[0] = 0, p[1] = 0, p[2] = 0, p[3] = static_cast<std::uint8_t>(id);
    require(rpem::auth::sign(h.signers[static_cast<std::size_t>(h.sign_mode - 1)],
                             h.other_channel ? "RPEM_ESTIMATE" : kChannel, m));
  }
  return m;
}

void check_verdict(std::span<const std::uint8_t> bytes, const CommandPolicy& p, std::int64_t last, const Harness& h,
                   const CommandVerdict& v) {
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
  const bool required = p.authentication == rpem::daemon::CommandAuthentication::kRequired;
  if (!p.enabled) {
    expected = CommandResult::kRejectedDisabled;
  } else if (required && m.key_id == 0) {
    expected = CommandResult::kRejectedUnauthenticated;
  } else if (required && m.key_id != 1 && m.key_id != 2) {
    expected = CommandResult::kRejectedUnknownKey;
  } else if (required && !h.authentic()) {
    expected = CommandResult::kRejectedBadMac;
  } else if (m.seq <= last) {
    expected = CommandResult::kRejectedOldSequence;
  } else if (!known) {
    expected = CommandResult::kRejectedUnknown;
  } else if (m.command == rpem::command_t::SET_VALUES && !values) {
    expected = CommandResult::kRejectedBadValues;
  }
  require(v.result == expected);
  require(v.key_id == m.key_id);
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
  if (size < 10) return 0;
  const std::uint8_t flags = data[0], auth = data[1];
  const auto mode = (auth & 1) ? rpem::daemon::CommandAuthentication::kRequired : rpem::daemon::CommandAuthentication::kNone;
  CommandPolicy policy{(flags & 1) != 0, 0.5, 1.7, 1.0, 4.5, mode};
  if (flags & 2) policy = {(flags & 1) != 0, 1.0, 1.2, 2.0, 2.5, mode};
  Harness h;
  h.sign_mode = (auth >> 1) & 3;
  h.other_channel = (auth & 8) != 0;
  std::int64_t last = 0;
  std::memcpy(&last, data + 2, sizeof last);
  // One copy of the input, exactly its size (ASan sees a read past the last message), in which the
  // messages are signed where they lie; each message is a span of it.
  std::vector<std::uint8_t> copy(data, data + size);
  std::vector<std::span<const std::uint8_t>> messages;
  for (std::size_t at = 10; at < size;) {
    const std::size_t n = std::min<std::size_t>(data[at], size - at - 1);
    messages.push_back(prepare(std::span(copy.data() + at + 1, n), h));
    at += 1 + n;
  }

  for (const auto& message : messages) {
    check_verdict(message, policy, last, h, rpem::daemon::admit_command(message, policy, h.held, kChannel, last));
  }

  // The loop's queue is built once (it allocates its Commands, 1 kB each) and is empty between inputs.
  static auto to_loop = rpem::daemon::SpscQueue<Command>::make(4);
  static Command c;
  require(!to_loop.consumer.pop(c));
  rpem::daemon::CommandKeys keys;
  keys.keys = held_keys();
  rpem::daemon::CommandGate gate(policy, to_loop.producer, std::move(keys));
  std::int64_t queued = 0, previous = INT64_MIN;
  auto pop = [&] {
    while (to_loop.consumer.pop(c)) {
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
