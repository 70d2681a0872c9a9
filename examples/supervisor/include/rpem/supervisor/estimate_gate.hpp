#pragma once
// Which RPEM_ESTIMATE messages the supervisor acts on (docs/supervisor.md, "What is ignored"), checked
// in this order on the bytes as received:
//   1. authentic — the MAC verifies under a publish key held (auth/: rpem::auth::verify), before a byte
//      of it is decoded; then it must decode as exactly one estimate_t (else malformed);
//   2. fresh — its utime, against the supervisor's clock: now − utime ≤ max_age + max_skew (not stale)
//      and utime − now ≤ max_skew (not from the future);
//   3. live — rpemd's state running: starting, stale (no samples) and stopping estimates hold values no
//      sample renewed;
//   4. newer — per key id, utime and sample_time_us strictly larger than those of the last estimate
//      accepted under that key id. A copy of a genuine message re-sent later (a replay: a cold magnet
//      an hour ago) fails 2 or, inside the freshness window, 4; so does a reordered one.
// The sample time is the drive's clock, which starts again when rpemd does: after a silence (the last
// accepted estimate under the key id no longer fresh by 2) the first fresh, live, newer-utime estimate sets
// its baseline anew. That opens nothing to an attacker — what passes 1–4 is new from rpemd's hand.

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "rpem/auth/mac.hpp"
#include "rpem/estimate_t.hpp"

namespace rpem::supervisor {

struct Freshness {
  std::int64_t max_age_us = 0;   ///< > 0: older estimates are stale (and so is the output built on them)
  std::int64_t max_skew_us = 0;  ///< ≥ 0: how far the two clocks may disagree

  /// An estimate `age_us` = now − utime old is stale: older than max_age, even allowing for the skew.
  [[nodiscard]] constexpr bool stale(std::int64_t age_us) const noexcept { return age_us > max_age_us + max_skew_us; }
  /// … or from the future: newer than now, beyond the skew.
  [[nodiscard]] constexpr bool from_future(std::int64_t age_us) const noexcept { return -age_us > max_skew_us; }
};

/// The gate's verdict on one message (stable numbers: counted and printed).
enum class Admission : std::int8_t {
  kAccepted = 0,
  kUnsigned = 1,    ///< key id 0
  kUnknownKey = 2,  ///< a key id not held
  kBadMac = 3,      ///< forged or altered
  kMalformed = 4,   ///< too short to carry the trailer, or (authentic) not exactly one estimate_t
  kStale = 5,       ///< older than max_age + max_skew
  kFromFuture = 6,  ///< newer than now + max_skew
  kNotNewer = 7,    ///< utime or sample time not past the last accepted one's: a replay or reordered
  kNotRunning = 8,  ///< rpemd's state not running (starting, stale, stopping): its estimates are held values
};
inline constexpr int kAdmissionCount = 9;
[[nodiscard]] const char* to_string(Admission a) noexcept;
/// Whether the gate got as far as decoding the message (it was authentic and well-formed).
[[nodiscard]] constexpr bool decoded(Admission a) noexcept { return a >= Admission::kStale || a == Admission::kAccepted; }

/// When an estimate was published and of which sample.
struct Stamp {
  std::int64_t utime_us = 0;
  std::int64_t sample_time_us = 0;
};

class EstimateGate {
 public:
  EstimateGate(const auth::Keyring& keys, Freshness freshness) noexcept : keys_(keys), freshness_(freshness) {}

  /// Decides on `encoded` (received on `channel`) at `now_unix_us`; decodes it into `out` once it is
  /// authentic (`out` is left alone before); on acceptance remembers its stamp under its key id. Counts
  /// every verdict. Allocates only for the estimate's string.
  Admission admit(std::string_view channel, std::span<const std::uint8_t> encoded, std::int64_t now_unix_us,
                  rpem::estimate_t& out) noexcept;

  [[nodiscard]] std::int64_t count(Admission a) const noexcept { return counts_[static_cast<std::size_t>(a)]; }
  [[nodiscard]] const Freshness& freshness() const noexcept { return freshness_; }

 private:
  /// The last accepted stamp under `key_id` (one per key of the keyring, in its order).
  [[nodiscard]] Stamp& last_of(std::int32_t key_id) noexcept;

  const auth::Keyring& keys_;
  Freshness freshness_;
  std::array<Stamp, auth::kMaxKeys> last_{};
  std::array<std::int64_t, kAdmissionCount> counts_{};
};

}  // namespace rpem::supervisor
