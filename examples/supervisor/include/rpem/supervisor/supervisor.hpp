#pragma once
// The supervisory controller's state: the publish keys, the gate (estimate_gate.hpp) and the last
// accepted estimate's temperatures, from which it derates the current (derating.hpp) at any moment.
// One thread owns it (the example's LCM loop). docs/supervisor.md.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "rpem/auth/mac.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/supervisor/config.hpp"
#include "rpem/supervisor/derating.hpp"
#include "rpem/supervisor/estimate_gate.hpp"

namespace rpem::supervisor {

/// The magnet's and the winding's temperatures an estimate gives (as of its utime): the fused ones when
/// its thermal model runs, else the raw RPEM-derived ones while valid; empty where it gives none
/// (not valid, source "none", not finite).
struct PartReadings {
  std::optional<TemperatureEstimate> magnet, winding;
};
[[nodiscard]] PartReadings readings_of(const rpem::estimate_t& m, const Config& config) noexcept;

/// The derated current at one moment, and why.
struct CurrentLimit {
  double current_A = 0.0;                                 ///< I_max
  double magnet_A = 0.0, winding_A = 0.0;                 ///< I_magnet, I_winding
  std::optional<double> magnet_upper_C, winding_upper_C;  ///< T⁺; empty: unknown
  bool fresh = false;                                     ///< built on an accepted estimate that is not stale
};

/// The gate's verdict on a message, and its utime where it was decoded (authentic).
struct Received {
  Admission verdict = Admission::kMalformed;
  std::optional<std::int64_t> utime_us;
};

class Supervisor {
 public:
  Supervisor(const Config& config, auth::Keyring&& keys) noexcept
      : config_(config), keys_(std::move(keys)), gate_(keys_, config.freshness) {}
  Supervisor(const Supervisor&) = delete;  // the gate holds the keyring by reference
  Supervisor& operator=(const Supervisor&) = delete;

  /// An RPEM_ESTIMATE's bytes as received on `channel` (LCM's raw subscription: never decoded before
  /// they are verified) at `now_unix_us`.
  Received on_message(std::string_view channel, std::span<const std::uint8_t> encoded, std::int64_t now_unix_us) noexcept;

  /// I_max at `now_unix_us`: from the last accepted estimate while it is fresh, each part's value aged
  /// by the time since; from nothing (every part at its floor) otherwise.
  [[nodiscard]] CurrentLimit current_limit(std::int64_t now_unix_us) const noexcept;

  [[nodiscard]] const EstimateGate& gate() const noexcept { return gate_; }

 private:
  struct Accepted {
    std::int64_t utime_us = 0;
    PartReadings readings;
  };

  Config config_;
  auth::Keyring keys_;
  EstimateGate gate_;
  std::optional<Accepted> last_;
};

}  // namespace rpem::supervisor
