#include "rpem/daemon/command_gate.hpp"

#include <array>

#include "rpem/command_t.hpp"
#include "rpem/core/assert.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;

constexpr std::array<CounterRow<CommandGate::Counters>, 7> kGateRows{{
    {&CommandGate::Counters::received, &Diag::commands_received},
    {&CommandGate::Counters::malformed, &Diag::commands_malformed},
    {&CommandGate::Counters::rejected, &Diag::commands_rejected},
    {&CommandGate::Counters::unauthenticated, &Diag::commands_unauthenticated},
    {&CommandGate::Counters::unknown_key, &Diag::commands_unknown_key},
    {&CommandGate::Counters::bad_mac, &Diag::commands_bad_mac},
    {&CommandGate::Counters::replayed, &Diag::commands_replayed},
}};

bool inside(double v, double lo, double hi) noexcept { return v >= lo && v <= hi; }  // false for NaN

CommandResult result_of(auth::Verdict v) noexcept {
  switch (v) {
    case auth::Verdict::kVerified:
      return CommandResult::kApplied;
    case auth::Verdict::kUnsigned:
      return CommandResult::kRejectedUnauthenticated;
    case auth::Verdict::kUnknownKey:
      return CommandResult::kRejectedUnknownKey;
    case auth::Verdict::kBadMac:
    case auth::Verdict::kMalformed:
      break;  // a decoded command_t always holds the trailer
  }
  return CommandResult::kRejectedBadMac;
}

}  // namespace

CommandPolicy CommandPolicy::of(const LiveConfig& live) noexcept {
  const core::EstimatorSettings& e = live.machine.estimator;
  return {live.commands_enabled, e.psi_m_min_Wb, e.psi_m_max_Wb, e.r_s_min_Ohm, e.r_s_max_Ohm, live.command_authentication};
}

CommandVerdict admit_command(std::span<const std::uint8_t> message, const CommandPolicy& policy, const auth::Keyring& keys,
                             std::string_view channel, std::int64_t last_accepted_seq) noexcept {
  CommandVerdict v;
  // 1. Decode: exactly one command_t (its fingerprint, its fields), no trailing bytes. Value-initialised: where
  // g++ inlines more of LCM's decoder (a unity batch) it does not see that a decode returning `size` wrote every
  // field read below (-Wmaybe-uninitialized); the decoder's integer stores into double fields are read back because
  // every user of the generated types compiles with -fno-strict-aliasing (lcm_types/CMakeLists.txt).
  rpem::command_t m{};
  const int size = message.size() > static_cast<std::size_t>(INT32_MAX) ? -1 : static_cast<int>(message.size());
  if (size < 0 || m.decode(message.data(), 0, size) != size) return v;
  v.decoded = true;
  v.command.seq = m.seq;
  v.key_id = m.key_id;
  auto refuse = [&](CommandResult why) {
    v.result = why;
    return v;
  };
  // 2. Enabled.
  if (!policy.enabled) return refuse(CommandResult::kRejectedDisabled);
  // 3. Authenticate: over the bytes as received (rpem/auth/mac.hpp), before any field is trusted.
  if (policy.authentication == CommandAuthentication::kRequired) {
    const CommandResult r = result_of(auth::verify(keys, channel, message));
    if (r != CommandResult::kApplied) return refuse(r);
  }
  // 4. Admit.
  if (m.seq <= last_accepted_seq) return refuse(CommandResult::kRejectedOldSequence);
  AdmittedCommand& c = v.command;
  switch (m.command) {
    case rpem::command_t::RESET:
      c.kind = Command::Kind::kReset;
      break;
    case rpem::command_t::FREEZE:
      c.kind = Command::Kind::kFreeze;
      break;
    case rpem::command_t::UNFREEZE:
      c.kind = Command::Kind::kUnfreeze;
      break;
    case rpem::command_t::SET_VALUES:
      if (!inside(m.psi_m_Wb, policy.psi_m_min_Wb, policy.psi_m_max_Wb) ||
          !inside(m.r_s_Ohm, policy.r_s_min_Ohm, policy.r_s_max_Ohm)) {
        return refuse(CommandResult::kRejectedBadValues);
      }
      c.kind = Command::Kind::kSetValues;
      c.psi_m_Wb = m.psi_m_Wb;
      c.r_s_Ohm = m.r_s_Ohm;
      break;
    default:
      return refuse(CommandResult::kRejectedUnknown);
  }
  v.result = CommandResult::kApplied;
  return v;
}

bool CommandGate::handle(std::span<const std::uint8_t> message, bool commit_now) noexcept {
  ++counters_.received;
  CommandVerdict v = admit_command(message, policy_, keys_.keys, keys_.channel, last_accepted_seq_);
  if (!v.decoded) {
    ++counters_.malformed;
    return false;
  }
  // 5. Queue: room for it beside the pending ones (this thread is the one producer, so room stays).
  if (v.result == CommandResult::kApplied && to_loop_.size() + n_pending_ >= to_loop_.capacity()) {
    v.result = CommandResult::kRejectedBusy;
  }
  if (v.result == CommandResult::kApplied) {
    if (n_pending_ == kMaxPending) (void)queue_pending();
    RPEM_ASSERT(n_pending_ < kMaxPending, "a full pending list was committed");
    pending_[n_pending_++] = v.command;
    last_accepted_seq_ = v.command.seq;
  } else {
    ++counters_.rejected;
    counters_.unauthenticated += v.result == CommandResult::kRejectedUnauthenticated;
    counters_.unknown_key += v.result == CommandResult::kRejectedUnknownKey;
    counters_.bad_mac += v.result == CommandResult::kRejectedBadMac;
    counters_.replayed += v.result == CommandResult::kRejectedOldSequence;
  }
  last_verdict_seq_ = v.command.seq;
  last_key_id_ = v.key_id;
  last_result_ = v.result;
  check_counts();
  if (v.result != CommandResult::kApplied) return false;
  return !commit_now || commit();
}

void CommandGate::check_counts() const noexcept {
  RPEM_ASSERT(
      counters_.received == counters_.malformed + counters_.rejected + queued_count_ + static_cast<std::int64_t>(n_pending_),
      "every message received is malformed, rejected, queued or pending");
  RPEM_ASSERT(
      counters_.unauthenticated + counters_.unknown_key + counters_.bad_mac + counters_.replayed <= counters_.rejected,
      "the rejections counted by reason are among the rejections");
}

bool CommandGate::commit() noexcept {
  const bool durable = queue_pending();
  check_counts();
  return durable;
}

bool CommandGate::queue_pending() noexcept {
  if (n_pending_ == 0) return true;
  // The sequence number durable first, then the commands: a restart can never accept one again.
  const bool durable = store_ == nullptr || store_->store(last_accepted_seq_);
  if (durable) {
    for (std::size_t k = 0; k < n_pending_; ++k) {
      const AdmittedCommand& a = pending_[k];
      RPEM_ASSERT(k == 0 || a.seq > pending_[k - 1].seq, "commands are admitted in increasing sequence order");
      queued_.kind = a.kind;
      queued_.seq = a.seq;
      queued_.psi_m_Wb = a.psi_m_Wb;
      queued_.r_s_Ohm = a.r_s_Ohm;
      const bool pushed = to_loop_.push(queued_);
      RPEM_ASSERT(pushed, "room was checked in handle(), and this thread is the queue's one producer, so it stayed");
    }
    queued_count_ += static_cast<std::int64_t>(n_pending_);
    durable_seq_ = last_accepted_seq_;
  } else {
    counters_.rejected += static_cast<std::int64_t>(n_pending_);
    last_accepted_seq_ = durable_seq_;
    last_result_ = CommandResult::kRejectedNotPersisted;
  }
  n_pending_ = 0;
  return durable;
}

void CommandGate::report(DiagnosticsRows& rows) const noexcept { rows.set_all(kGateRows, counters_); }

}  // namespace rpem::daemon
