#include "rpem/daemon/command_gate.hpp"

#include <array>

#include "rpem/command_t.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;

constexpr std::array<CounterRow<CommandGate::Counters>, 3> kGateRows{{
    {&CommandGate::Counters::received, &Diag::commands_received},
    {&CommandGate::Counters::malformed, &Diag::commands_malformed},
    {&CommandGate::Counters::rejected, &Diag::commands_rejected},
}};

bool inside(double v, double lo, double hi) noexcept { return v >= lo && v <= hi; }  // false for NaN

}  // namespace

CommandPolicy CommandPolicy::of(const LiveConfig& live) noexcept {
  const core::EstimatorSettings& e = live.machine.estimator;
  return {live.commands_enabled, e.psi_m_min_Wb, e.psi_m_max_Wb, e.r_s_min_Ohm, e.r_s_max_Ohm};
}

CommandVerdict admit_command(std::span<const std::uint8_t> message, const CommandPolicy& policy,
                             std::int64_t last_accepted_seq) noexcept {
  CommandVerdict v;
  // 1. Decode: exactly one command_t (its fingerprint, its fields), no trailing bytes.
  rpem::command_t m;
  const int size = message.size() > static_cast<std::size_t>(INT32_MAX) ? -1 : static_cast<int>(message.size());
  if (size < 0 || m.decode(message.data(), 0, size) != size) return v;
  v.decoded = true;
  v.command.seq = m.seq;
  // 2. Authenticate: no step yet (see the header).
  // 3. Admit.
  auto refuse = [&](CommandResult why) {
    v.result = why;
    return v;
  };
  if (!policy.enabled) return refuse(CommandResult::kRejectedDisabled);
  if (m.seq <= last_accepted_seq) return refuse(CommandResult::kRejectedOldSequence);
  Command& c = v.command;
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

bool CommandGate::handle(std::span<const std::uint8_t> message) noexcept {
  ++counters_.received;
  CommandVerdict v = admit_command(message, policy_, last_accepted_seq_);
  if (!v.decoded) {
    ++counters_.malformed;
    return false;
  }
  // 4. Queue.
  if (v.result == CommandResult::kApplied && !to_loop_.push(v.command)) v.result = CommandResult::kRejectedBusy;
  if (v.result == CommandResult::kApplied) {
    last_accepted_seq_ = v.command.seq;
  } else {
    ++counters_.rejected;
  }
  last_verdict_seq_ = v.command.seq;
  last_result_ = v.result;
  return v.result == CommandResult::kApplied;
}

void CommandGate::report(DiagnosticsRows& rows) const noexcept { rows.set_all(kGateRows, counters_); }

}  // namespace rpem::daemon
