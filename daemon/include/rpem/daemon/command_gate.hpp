#pragma once
// RPEM_COMMAND's way in (docs/rpemd.md, "Commands"), on the control thread — the one producer of the
// loop's command queue. Every message passes these steps, in order:
//   1. decode       exactly one rpem.command_t, nothing more (else: malformed, counted, no verdict);
//   2. authenticate (the place for a message authentication step: key id, MAC and replay window are
//                   checked here, on the decoded message and its bytes, before anything is admitted);
//   3. admit        commands enabled, a sequence number above the last accepted one, a known command,
//                   values inside D_M of the configuration running now;
//   4. queue        to the loop, which applies it at the start of its next period (a full queue:
//                   rejected as busy, the sequence number not used up).
// admit_command() is steps 1–3 as a pure, total function of the bytes, the policy and the last
// accepted sequence number: no I/O, no allocation, no exception, whatever the bytes — the fuzzer's
// entry point (daemon/fuzz/fuzz_command.cpp). CommandGate keeps the state between messages.

#include <cstdint>
#include <span>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {

/// What admission checks against: the running configuration's switch and D_M.
struct CommandPolicy {
  bool enabled = false;
  double psi_m_min_Wb = 0.0, psi_m_max_Wb = 0.0;
  double r_s_min_Ohm = 0.0, r_s_max_Ohm = 0.0;
  [[nodiscard]] static CommandPolicy of(const LiveConfig& live) noexcept;
};

struct CommandVerdict {
  bool decoded = false;                         ///< false: not an rpem.command_t (malformed)
  CommandResult result = CommandResult::kNone;  ///< decoded: kApplied if admitted, else why not
  Command command;                              ///< decoded: its seq; admitted: the command for the loop
};

[[nodiscard]] CommandVerdict admit_command(std::span<const std::uint8_t> message, const CommandPolicy& policy,
                                           std::int64_t last_accepted_seq) noexcept;

class CommandGate {
 public:
  struct Counters {
    std::int64_t received = 0;
    std::int64_t malformed = 0;
    std::int64_t rejected = 0;  ///< decoded but refused (disabled, old sequence, bad values, unknown, busy)
  };

  CommandGate(const CommandPolicy& policy, SpscQueue<Command>& to_loop) noexcept : policy_(policy), to_loop_(to_loop) {}

  /// A reload's new policy: every later message is admitted against it.
  void set_policy(const CommandPolicy& policy) noexcept { policy_ = policy; }
  /// One RPEM_COMMAND message, through every step. True if it was queued for the loop.
  bool handle(std::span<const std::uint8_t> message) noexcept;

  [[nodiscard]] const CommandPolicy& policy() const noexcept { return policy_; }
  [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
  [[nodiscard]] std::int64_t last_seq() const noexcept { return last_verdict_seq_; }
  [[nodiscard]] CommandResult last_result() const noexcept { return last_result_; }
  /// The counters as diagnostics rows.
  void report(DiagnosticsRows& rows) const noexcept;

 private:
  CommandPolicy policy_;
  SpscQueue<Command>& to_loop_;
  Counters counters_;
  std::int64_t last_accepted_seq_ = 0;
  std::int64_t last_verdict_seq_ = 0;
  CommandResult last_result_ = CommandResult::kNone;
};

}  // namespace rpem::daemon
