#pragma once
// The VESC source's poll schedule and reply state machine, without the socket (docs/rpemd.md,
// "source: vesc"; the protocol: docs/can-vesc.md). Pure and allocation-free: the source thread gives it
// the time and every received frame with its kernel receive time; it says when to poll and turns each
// reply into an averaged rotor-frame sample, its speed the window's mean rebuilt from the PLL's speed at
// this read and the previous one (the reply's ERPM is the PLL's at the read).
//
// Schedule: polls at t = k·T + φ·T on the host's clock (T = 1/poll_rate_Hz, φ = poll_phase), so
// instances polling drives on one bus interleave instead of colliding. One poll awaits its reply at a time
// (a second may still be receiving one: "answered" below); it times out after reply_timeout_s.
//
// Windows: VESC's i_d, i_q, v_d, v_q are averages since the previous read by anyone, reset by each read
// (docs/can-vesc.md, "What the values mean"). A reply's window therefore ends at the receive time of its
// first frame and starts at the newest earlier read seen: the previous reply, or a read of this
// controller by another poller seen on the bus. Stealing and the other irregularities are detected so:
//   stolen_reads      a COMM_GET_VALUES(_SELECTIVE) request to this controller on the bus: never ours (a
//                     raw socket does not receive its own frames), so another poller reset the averages
//                     there; the next window starts at it.
//   unrequested       a values reply to our id with no poll of ours outstanding or timed out unanswered
//                     in the last period: another poller uses our host id. Its window is still right
//                     (it ends a read), so it is used.
//   (answered)        a poll whose reply's first frame came within reply_timeout_s is answered, however long
//                     the rest of the reply takes on the bus: at 1 kHz on a 1 Mbit/s bus a reply alone takes
//                     0.9 ms and its frames straddle the next poll. That poll then takes the outstanding slot
//                     and the one being answered a second slot, until its reply completes (counted as
//                     neither timeout nor late), is refused by the decoder, gives way to a newer reply, or
//                     runs a further period past its deadline (then it times out).
//   late              a reply to a poll that had timed out (within one period of the timeout): used, and
//                     the gap the timeout feared is lifted (this reply is that read). A reply under way is
//                     never discarded by a timeout. While the next poll is out, a reply is the timed-out
//                     poll's only if it began before that poll went out; one that began after it is the
//                     outstanding poll's. So a poll lost once (a silence, the controller not yet up) leaves
//                     no chain of "late" replies and timeouts behind it, and a reply lost later keeps its
//                     gap. Replies slower than a whole period are taken one poll on, their windows
//                     unchanged: one gap where they start being so slow, one `unrequested` where they stop.
//   timeouts          a poll whose reply did not begin within reply_timeout_s (silent controller, lost
//                     frames), or began and never completed. Whether the controller read (and reset) is
//                     unknown, so the next window follows a gap.
//   short_windows     a window shorter than kMinWindow: the firmware divides sums of (nearly) no control
//                     cycles — not a measurement; dropped, the next window follows a gap.
//   empty_reads       a reply whose i_d, i_q, v_d, v_q are all exactly 0: what the firmware sends for a read
//                     with no control cycle since the previous one (0/0 in mc_interface_read_reset_avg_*,
//                     NaN cast to 0 by the Cortex-M4; docs/can-vesc.md). A measured window never gives four
//                     exact zeros unless the machine stands unexcited, which carries nothing to estimate
//                     from either; dropped, the next window follows a gap.
//   long_windows      a window longer than 2·period + timeout: the longest a single lost read explains (a
//                     reply late by up to a period after its timeout closes a window of at most that), so
//                     more means the controller went unread (silent, off the bus) and the average spans
//                     unknown operation — not a sample of the steady-state model; dropped, the next window
//                     follows a gap.
// Reads by a poller the bus does not show (VESC Tool over USB or UART) shorten windows invisibly: the
// reply carries no count of the cycles averaged (docs/rpemd.md says what that costs).

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "rpem/can/vesc.hpp"
#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/reported_speed.hpp"

namespace rpem::daemon {

struct VescPollerCounters {
  std::uint64_t polls = 0;
  std::uint64_t send_failures = 0;
  std::uint64_t samples = 0;  ///< windows delivered
  std::uint64_t timeouts = 0;
  std::uint64_t late = 0;
  std::uint64_t unrequested = 0;
  std::uint64_t stolen_reads = 0;
  std::uint64_t short_windows = 0;
  std::uint64_t empty_reads = 0;
  std::uint64_t long_windows = 0;
  /// Windows delivered without a winding reading: the reply's motor temperature is the firmware's value for none
  /// (can::vesc::kNoMotorReading_C: an open, shorted or absent sensor).
  std::uint64_t no_motor_reading = 0;
};

class VescPoller {
 public:
  struct Config {
    std::uint8_t controller_id = 0;
    std::uint8_t host_id = 254;
    std::int64_t period_ns = 5'000'000;
    std::int64_t phase_ns = 0;  ///< in [0, period_ns)
    std::int64_t timeout_ns = 4'500'000;
    std::uint32_t mask = can::vesc::kEstimatorMask;
    /// The reply's ERPM is the firmware's PLL speed at the read, lagging a ramp by k_p/k_i: each window's mean
    /// speed is rebuilt from it and the previous reply's (core::window_mean_speed_rad_s; docs/derivations.md §13,
    /// "Speed at the read"). Its error is SpeedErrorDelay's, from last_accel_change_rad_s2 at both its ends.
    core::PllGains pll{can::vesc::kDefaultPllKp, can::vesc::kDefaultPllKi};
  };
  /// Shorter windows are not measurements (a few of VESC's control cycles at most).
  static constexpr std::int64_t kMinWindowNs = 200'000;
  /// COMM_PACKET_IDs whose reply reads and resets the averages (datatypes.h; commands.c).
  static constexpr std::uint8_t kCommGetValues = 4;

  explicit VescPoller(const Config& config) noexcept;

  /// When the next poll is due (host ns), the first at or after `now_ns` on the schedule.
  [[nodiscard]] std::int64_t next_poll_ns(std::int64_t now_ns) const noexcept;
  /// The next moment the poller needs the time — a poll due or an outstanding reply's deadline — and
  /// `now_ns` when that has passed.
  [[nodiscard]] std::int64_t wake_ns(std::int64_t now_ns) const noexcept;
  /// The poll frame (COMM_GET_VALUES_SELECTIVE with the mask, to the controller, from host_id).
  [[nodiscard]] const can::CanFrame& poll_frame() const noexcept { return poll_; }
  /// True when a poll is due at `now_ns` (the caller sends poll_frame() and calls polled()).
  [[nodiscard]] bool poll_due(std::int64_t now_ns) const noexcept { return now_ns >= next_due_ns_; }
  /// The poll went out at `now_ns` (or could not be sent).
  void polled(std::int64_t now_ns, bool sent) noexcept;
  /// Time passes: an outstanding poll past its deadline times out.
  void on_time(std::int64_t now_ns) noexcept;
  /// One received frame with its receive time: true when it completes a reply whose window is a
  /// sample (written to `sample`).
  [[nodiscard]] bool on_frame(const can::CanFrame& f, std::int64_t rx_ns, core::AveragedSample& sample) noexcept;

  /// Replies decoded so far, and the newest one's read of the tachometer (its time, the steps as an angle; 0
  /// where the mask leaves it out): what CountDelay counts the windows' speeds from.
  [[nodiscard]] std::uint64_t reads() const noexcept { return reads_; }
  [[nodiscard]] const core::CountRead& last_read() const noexcept { return last_read_; }
  /// The change of the PLL's mean acceleration the newest reply shows over the last three
  /// (core::read_accel_change_rad_s2); NaN where that reply closed no sample or fewer than three were read.
  [[nodiscard]] double last_accel_change_rad_s2() const noexcept { return last_accel_change_rad_s2_; }

  [[nodiscard]] const VescPollerCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const can::vesc::VescDecoder& decoder() const noexcept { return decoder_; }
  /// True while no reply came for the last poll(s): the controller is silent.
  [[nodiscard]] bool silent() const noexcept { return consecutive_timeouts_ > 0; }

 private:
  /// Counts a poll that timed out at `at_ns`, its deadline (the caller has cleared its slot).
  void time_out(std::int64_t at_ns) noexcept;
  /// When the outstanding poll's reply must have begun: sent_ns_ + timeout.
  [[nodiscard]] std::int64_t deadline_ns() const noexcept;
  /// The outstanding poll's reply has begun, within its timeout, and is still arriving.
  [[nodiscard]] bool reply_under_way() const noexcept;
  /// When the outstanding poll times out: its deadline, or a period later while its reply is under way.
  [[nodiscard]] std::int64_t outstanding_deadline_ns() const noexcept;
  [[nodiscard]] bool is_values_read_of_controller(const can::CanFrame& f) const noexcept;
  [[nodiscard]] bool starts_reply(const can::CanFrame& f) const noexcept;
  /// The frame that closes a reply to us (the decoder processes the reply at it).
  [[nodiscard]] bool ends_reply(const can::CanFrame& f) const noexcept;
  /// Drops a window that is no measurement (counted); true when `t` closes a usable one.
  [[nodiscard]] bool plausible_window(std::int64_t t) noexcept;

  Config config_;
  can::CanFrame poll_;
  can::vesc::VescDecoder decoder_;
  VescPollerCounters counters_;
  std::int64_t next_due_ns_ = 0;  ///< 0: the first call to poll_due() is due
  bool outstanding_ = false;      ///< the newest poll, awaiting its reply
  std::int64_t sent_ns_ = 0;      ///< when it went out; its reply's first frame is due by deadline_ns()
  bool answering_ = false;        ///< the second slot: an earlier poll whose reply began in time, still arriving
  std::int64_t answering_deadline_ns_ = 0;
  bool timed_out_unanswered_ = false;
  std::int64_t timed_out_at_ns_ = 0;
  std::int64_t consecutive_timeouts_ = 0;
  std::int64_t reply_start_ns_ = 0;  ///< receive time of the reply's first frame
  bool has_window_start_ = false;
  std::int64_t window_start_ns_ = 0;  ///< the newest read of the controller seen
  core::SpeedRead previous_speed_;    ///< the PLL's speed in our previous reply, and when it was read
  core::SpeedRead earlier_speed_;     ///< the same in the reply before it
  int speeds_seen_ = 0;               ///< replies whose speed is in previous_speed_ and earlier_speed_ (at most 2)
  double last_accel_change_rad_s2_ = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t reads_ = 0;
  core::CountRead last_read_;
  bool gap_ = true;                 ///< windows before the next may be lost
  bool gap_before_timeout_ = true;  ///< gap_ as it was before the newest timeout (a late reply restores it)
};

}  // namespace rpem::daemon
