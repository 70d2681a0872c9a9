#pragma once
// `source: {type: vesc, vesc: {interface: can0, controller_id: 17, host_id: 125, poll_rate_Hz: 200}}` —
// a VESC (vedderb/bldc) polled over SocketCAN with COMM_GET_VALUES_SELECTIVE (docs/can-vesc.md): each reply
// is an averaged rotor-frame sample over [previous reply, this reply] (host receive times), stepped by the
// averaged estimator (docs/rpemd.md, "source: vesc"). The poll schedule and the reply state machine are
// VescPoller (vesc_poller.hpp), testable without a socket.

#include <memory>
#include <string>

#include "rpem/daemon/source.hpp"
#include "rpem/daemon/vesc_poller.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::daemon {

struct VescSource {
  static constexpr const char* kType = "vesc";
  struct Options {
    std::string interface = "can0";
    int controller_id = 0;        ///< the VESC's CAN id (its app configuration's controller_id), 0–254
    int host_id = 254;            ///< rpemd's node id on the bus, where replies are addressed; no VESC may use it
    double poll_rate_Hz = 200.0;  ///< 1–2000 Hz
    /// Where in each poll period this instance polls, as a fraction of the period: instances polling
    /// drives on one bus take different phases (docs/rpemd.md, "Several drives on one bus").
    double poll_phase = 0.0;
    /// A reply not begun this long after its poll is a timeout (default: 0.9 poll periods, at most 20 ms); one begun
    /// in time may take longer to complete (the reply alone takes ~0.9 ms of a 1 Mbit/s bus: VescPoller).
    double reply_timeout_s = 0.0;
    /// The firmware's PLL gains (its motor configuration's foc_pll_kp, foc_pll_ki): the ERPM it reports lags a
    /// speed ramp by k_p/k_i, which each window's mean speed allows for (docs/rpemd.md, "source: vesc").
    double pll_kp = can::vesc::kDefaultPllKp;
    double pll_ki = can::vesc::kDefaultPllKi;
    /// How long each window waits for its speed to be counted from the tachometer, which the polls then ask
    /// for (CountDelay; core::kCountRunSideMaxS): not a key of the section, but the machine's — set where its
    /// angle is a Hall drive's staircase (regimes.angle_source: hall), 0 otherwise (no count, no wait).
    double count_horizon_s = 0.0;
    bool operator==(const Options&) const = default;
  };
  [[nodiscard]] static Options parse(io::YamlMap& section, const std::string& base_dir);
  [[nodiscard]] static SampleKind sample_kind(const Options&) noexcept { return SampleKind::kAveraged; }
  /// A reply, and with it a window, every poll period T, each up to reply_timeout_s after its poll: T + timeout
  /// apart at most, 2·T + timeout where one reply is lost (the longest window VescPoller keeps).
  [[nodiscard]] static SampleSpacing sample_spacing(const Options& o) noexcept {
    const double period_s = 1.0 / o.poll_rate_Hz;
    return {period_s + o.reply_timeout_s, 2.0 * period_s + o.reply_timeout_s};
  }
  [[nodiscard]] static std::unique_ptr<SampleSource> make(const Options& options);
};

/// The poller's schedule and ids from the options.
[[nodiscard]] VescPoller::Config poller_config(const VescSource::Options& options) noexcept;
/// How long the source waits, once a reply has begun to arrive, before it reads the bus again: a reply is
/// several frames (six for the estimator's mask), so it wakes once for them instead of once per frame. The
/// frames keep their kernel receive times, so only the hand-over to the loop waits:
///   gather = min(1 ms, poll period / 16)     (1 ms at 56 Hz, 62.5 µs at 1 kHz)
[[nodiscard]] std::int64_t reply_gather_ns(std::int64_t poll_period_ns) noexcept;
/// The poller's and its decoder's counters as diagnostics rows (vesc_*, can_*).
void report_vesc_counters(const VescPoller& poller, DiagnosticsRows& rows) noexcept;

}  // namespace rpem::daemon
