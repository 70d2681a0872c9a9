#pragma once
// RPEM_COMMAND's way in (docs/rpemd.md, "Commands" and "Authentication"), on the control thread — the
// one producer of the loop's command queue. Every message passes these steps, in order:
//   1. decode       exactly one rpem.command_t, nothing more (else: malformed, counted, no verdict);
//   2. enabled      commands enabled by the running configuration;
//   3. authenticate its key id names a key rpemd holds and its MAC verifies under it (rpem/auth/mac.hpp),
//                   unless the configuration says `authentication: none` (local only);
//   4. admit        a sequence number above the last accepted one (ever: persisted before it is
//                   used), a known command, values inside D_M of the configuration running now;
//   5. queue        to the loop, which applies it at the start of its next period (a full queue:
//                   rejected as busy, the sequence number not used up) — once the highest accepted
//                   sequence number is durable. The control thread admits a whole wake's messages and
//                   then commits them with one write (handle(…, false) … commit()), so one fsync
//                   covers a burst.
// admit_command() is steps 1–4 as a pure, total function of the bytes, the policy, the keys and the
// last accepted sequence number: no I/O, no allocation, no exception, whatever the bytes — the
// fuzzer's entry point (daemon/fuzz/fuzz_command.cpp). CommandGate keeps the state between messages.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "rpem/auth/mac.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/diagnostics_rows.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {

/// What admission checks against: the running configuration's switches and D_M.
struct CommandPolicy {
  bool enabled = false;
  double psi_m_min_Wb = 0.0, psi_m_max_Wb = 0.0;
  double r_s_min_Ohm = 0.0, r_s_max_Ohm = 0.0;
  CommandAuthentication authentication = CommandAuthentication::kRequired;
  [[nodiscard]] static CommandPolicy of(const LiveConfig& live) noexcept;
};

/// Whom commands must come from: the accepted keys and the channel name the MAC covers.
struct CommandKeys {
  auth::Keyring keys;
  std::string channel = "RPEM_COMMAND";
};

/// A command as admission decides it: the fields of the loop's Command that an RPEM_COMMAND sets. (A
/// Command also carries a reload's whole LiveConfig, about 1 kB, which no RPEM_COMMAND uses: verdicts
/// and the gate's pending commands stay small, and the gate builds a Command only to queue one.)
struct AdmittedCommand {
  Command::Kind kind = Command::Kind::kReset;
  std::int64_t seq = 0;
  double psi_m_Wb = 0.0;  ///< kSetValues
  double r_s_Ohm = 0.0;
};

struct CommandVerdict {
  bool decoded = false;                         ///< false: not an rpem.command_t (malformed)
  CommandResult result = CommandResult::kNone;  ///< decoded: kApplied if admitted, else why not
  std::int32_t key_id = 0;                      ///< decoded: the key id it names
  AdmittedCommand command;                      ///< decoded: its seq; admitted: the command for the loop
};

[[nodiscard]] CommandVerdict admit_command(std::span<const std::uint8_t> message, const CommandPolicy& policy,
                                           const auth::Keyring& keys, std::string_view channel,
                                           std::int64_t last_accepted_seq) noexcept;

/// Where the last accepted sequence number survives a restart (Control: a file in the state directory).
class SequenceStore {
 public:
  virtual ~SequenceStore() = default;
  /// True once `seq` is durable.
  virtual bool store(std::int64_t seq) noexcept = 0;
};

class CommandGate {
 public:
  struct Counters {
    std::int64_t received = 0;
    std::int64_t malformed = 0;
    std::int64_t rejected = 0;  ///< decoded but refused, for any reason; among them:
    std::int64_t unauthenticated = 0;
    std::int64_t unknown_key = 0;
    std::int64_t bad_mac = 0;
    std::int64_t replayed = 0;  ///< authentic (or not required to be) but an old sequence number
  };

  /// `last_accepted_seq`: as persisted by `store` (nullptr: not persisted — tests).
  CommandGate(const CommandPolicy& policy, SpscQueue<Command>::Producer& to_loop, CommandKeys keys = {},
              std::int64_t last_accepted_seq = 0, SequenceStore* store = nullptr) noexcept
      : policy_(policy),
        to_loop_(to_loop),
        keys_(std::move(keys)),
        store_(store),
        last_accepted_seq_(last_accepted_seq),
        durable_seq_(last_accepted_seq) {}

  /// A reload's new policy: every later message is admitted against it.
  void set_policy(const CommandPolicy& policy) noexcept { policy_ = policy; }
  /// One RPEM_COMMAND message, through every step. True if it was admitted: queued for the loop, or
  /// with `commit_now` false pending until commit().
  bool handle(std::span<const std::uint8_t> message, bool commit_now = true) noexcept;
  /// Makes the highest admitted sequence number durable, then queues the pending commands in order;
  /// if it cannot be made durable, rejects them all (kRejectedNotPersisted). False then.
  bool commit() noexcept;

  [[nodiscard]] const CommandPolicy& policy() const noexcept { return policy_; }
  [[nodiscard]] const CommandKeys& keys() const noexcept { return keys_; }
  [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
  [[nodiscard]] std::int64_t last_seq() const noexcept { return last_verdict_seq_; }
  [[nodiscard]] std::int64_t last_accepted_seq() const noexcept { return last_accepted_seq_; }
  [[nodiscard]] CommandResult last_result() const noexcept { return last_result_; }
  [[nodiscard]] std::int32_t last_key_id() const noexcept { return last_key_id_; }
  /// The counters as diagnostics rows.
  void report(DiagnosticsRows& rows) const noexcept;

 private:
  /// commit()'s work, also when the pending list is full in the middle of handle().
  bool queue_pending() noexcept;
  void check_counts() const noexcept;

  CommandPolicy policy_;
  SpscQueue<Command>::Producer& to_loop_;  ///< the control thread's (Control holds it)
  const CommandKeys keys_;
  SequenceStore* store_;
  Counters counters_;
  static constexpr std::size_t kMaxPending = 64;
  std::array<AdmittedCommand, kMaxPending> pending_{};
  std::size_t n_pending_ = 0;
  Command queued_;                 ///< what commit() pushes, one pending command at a time
  std::int64_t queued_count_ = 0;  ///< commands queued for the loop
  std::int64_t last_accepted_seq_ = 0;
  std::int64_t durable_seq_ = 0;  ///< the last accepted sequence number that is persisted
  std::int64_t last_verdict_seq_ = 0;
  std::int32_t last_key_id_ = 0;
  CommandResult last_result_ = CommandResult::kNone;
};

}  // namespace rpem::daemon
