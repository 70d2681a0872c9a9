#include "rpem/supervisor/estimate_gate.hpp"

#include "rpem/core/assert.hpp"
#include "rpem/schema/decode.hpp"

namespace rpem::supervisor {

const char* to_string(Admission a) noexcept {
  switch (a) {
    case Admission::kAccepted:
      return "accepted";
    case Admission::kUnsigned:
      return "unsigned";
    case Admission::kUnknownKey:
      return "unknown key";
    case Admission::kBadMac:
      return "bad MAC";
    case Admission::kMalformed:
      return "malformed";
    case Admission::kStale:
      return "stale";
    case Admission::kFromFuture:
      return "from the future";
    case Admission::kNotNewer:
      return "not newer (replayed or reordered)";
    case Admission::kNotRunning:
      return "not running (rpemd starting, stale or stopping)";
  }
  return "?";
}

Stamp& EstimateGate::last_of(std::int32_t key_id) noexcept {
  int k = 0;
  while (k < keys_.size() - 1 && keys_[k].id() != key_id) ++k;
  RPEM_ASSERT(keys_[k].id() == key_id, "a verified message's key id is one the keyring holds");
  return last_[static_cast<std::size_t>(k)];
}

Admission EstimateGate::admit(std::string_view channel, std::span<const std::uint8_t> encoded, std::int64_t now_unix_us,
                              rpem::estimate_t& out) noexcept {
  const Admission a = [&] {
    switch (auth::verify(keys_, channel, encoded)) {
      case auth::Verdict::kVerified:
        break;
      case auth::Verdict::kUnsigned:
        return Admission::kUnsigned;
      case auth::Verdict::kUnknownKey:
        return Admission::kUnknownKey;
      case auth::Verdict::kBadMac:
        return Admission::kBadMac;
      case auth::Verdict::kMalformed:
        return Admission::kMalformed;
    }
    if (!schema::decode_exactly(encoded, out)) return Admission::kMalformed;
    const Stamp stamp{out.utime, out.sample_time_us};
    const std::int64_t age_us = now_unix_us - stamp.utime_us;
    if (freshness_.stale(age_us)) return Admission::kStale;
    if (freshness_.from_future(age_us)) return Admission::kFromFuture;
    if (out.state != rpem::estimate_t::STATE_RUNNING) return Admission::kNotRunning;
    Stamp& last = last_of(auth::key_id_of(encoded));
    if (stamp.utime_us <= last.utime_us) return Admission::kNotNewer;
    const bool silence = freshness_.stale(now_unix_us - last.utime_us);  // rpemd may have restarted
    if (!silence && stamp.sample_time_us <= last.sample_time_us) return Admission::kNotNewer;
    last = stamp;
    return Admission::kAccepted;
  }();
  ++counts_[static_cast<std::size_t>(a)];
  return a;
}

}  // namespace rpem::supervisor
