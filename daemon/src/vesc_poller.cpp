#include "rpem/daemon/vesc_poller.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "rpem/core/assert.hpp"
#include "rpem/core/units.hpp"

namespace rpem::daemon {

namespace vesc = can::vesc;

VescPoller::VescPoller(const Config& config) noexcept
    : config_(config),
      poll_(vesc::values_request(config.controller_id, config.host_id, config.mask)),
      decoder_(config.controller_id, config.host_id, config.mask) {
  RPEM_ASSERT(config.timeout_ns <= config.period_ns,
              "a reply times out within its poll period: on_frame takes one begun after the next poll as that poll's");
}

std::int64_t VescPoller::next_poll_ns(std::int64_t now_ns) const noexcept {
  const std::int64_t T = config_.period_ns;
  const std::int64_t since = now_ns - config_.phase_ns;
  std::int64_t k = since / T;
  if (k * T < since) ++k;  // ceil, for either sign
  return k * T + config_.phase_ns;
}

std::int64_t VescPoller::deadline_ns() const noexcept { return sent_ns_ + config_.timeout_ns; }

bool VescPoller::reply_under_way() const noexcept {
  return outstanding_ && reply_start_ns_ != 0 && reply_start_ns_ >= sent_ns_ && reply_start_ns_ <= deadline_ns();
}

std::int64_t VescPoller::outstanding_deadline_ns() const noexcept {
  return reply_under_way() ? deadline_ns() + config_.period_ns : deadline_ns();
}

std::int64_t VescPoller::wake_ns(std::int64_t now_ns) const noexcept {
  std::int64_t next = next_due_ns_;
  if (outstanding_) next = std::min(next, outstanding_deadline_ns());
  if (answering_) next = std::min(next, answering_deadline_ns_);
  return std::max(next, now_ns);
}

void VescPoller::polled(std::int64_t now_ns, bool sent) noexcept {
  std::int64_t next = next_poll_ns(now_ns);
  if (next <= now_ns) next += config_.period_ns;
  next_due_ns_ = next;
  if (!sent) {
    ++counters_.send_failures;
    return;
  }
  if (outstanding_) {
    if (reply_under_way()) {
      // Its reply began in time and is still arriving (1 kHz on a 1 Mbit/s bus: a reply alone takes 0.9 ms):
      // the poll is answered, and keeps the second slot until the reply completes, fails or runs out of time.
      if (answering_) time_out(answering_deadline_ns_);
      answering_ = true;
      answering_deadline_ns_ = deadline_ns() + config_.period_ns;
    } else {
      time_out(deadline_ns());  // unanswered, where on_time did not see its deadline pass
    }
  }
  ++counters_.polls;
  outstanding_ = true;
  sent_ns_ = now_ns;
}

void VescPoller::on_time(std::int64_t now_ns) noexcept {
  if (answering_ && now_ns > answering_deadline_ns_) {
    answering_ = false;
    time_out(answering_deadline_ns_);
  }
  if (outstanding_ && now_ns > outstanding_deadline_ns()) {
    outstanding_ = false;
    time_out(deadline_ns());
  }
}

void VescPoller::time_out(std::int64_t at_ns) noexcept {
  ++counters_.timeouts;
  ++consecutive_timeouts_;
  timed_out_unanswered_ = true;
  timed_out_at_ns_ = at_ns;
  // The decoder's buffer is kept: a reply that began after the deadline may still complete (and is then late);
  // a new reply restarts it at offset 0 all the same.
  gap_before_timeout_ = gap_;
  gap_ = true;  // the controller may have read (and reset) with its reply lost
}

bool VescPoller::is_values_read_of_controller(const can::CanFrame& f) const noexcept {
  if (f.error || !f.extended || f.len < 3) return false;
  const std::uint32_t addressee = f.id & 0xFF;
  if (addressee != config_.controller_id && addressee != vesc::kBroadcastId) return false;
  if ((f.id >> 8) != static_cast<std::uint32_t>(vesc::Packet::kProcessShortBuffer)) return false;
  // [sender][commands_send][command …]
  return f.data[2] == kCommGetValues || f.data[2] == vesc::kCommGetValuesSelective;
}

bool VescPoller::starts_reply(const can::CanFrame& f) const noexcept {
  if (f.error || !f.extended || (f.id & 0xFF) != config_.host_id) return false;
  const std::uint32_t packet = f.id >> 8;
  if (packet == static_cast<std::uint32_t>(vesc::Packet::kProcessShortBuffer)) return true;
  return packet == static_cast<std::uint32_t>(vesc::Packet::kFillRxBuffer) && f.len >= 1 && f.data[0] == 0;
}

bool VescPoller::ends_reply(const can::CanFrame& f) const noexcept {
  if (f.error || !f.extended || (f.id & 0xFF) != config_.host_id) return false;
  const std::uint32_t packet = f.id >> 8;
  return packet == static_cast<std::uint32_t>(vesc::Packet::kProcessShortBuffer) ||
         packet == static_cast<std::uint32_t>(vesc::Packet::kProcessRxBuffer);
}

bool VescPoller::plausible_window(std::int64_t t) noexcept {
  const std::int64_t window_ns = t - window_start_ns_;
  if (window_ns < kMinWindowNs) {
    ++counters_.short_windows;
    return false;
  }
  if (window_ns > 2 * config_.period_ns + config_.timeout_ns) {
    ++counters_.long_windows;
    return false;
  }
  const vesc::Values& v = decoder_.values();
  if (v.i_d_A == 0.0 && v.i_q_A == 0.0 && v.v_d_V == 0.0 && v.v_q_V == 0.0) {
    ++counters_.empty_reads;
    return false;
  }
  return true;
}

bool VescPoller::on_frame(const can::CanFrame& f, std::int64_t rx_ns, core::AveragedSample& sample) noexcept {
  if (is_values_read_of_controller(f)) {
    ++counters_.stolen_reads;
    window_start_ns_ = rx_ns;  // the controller's averages restart here
  }
  if (starts_reply(f)) {
    // A reply the second slot still waited for can no longer complete: the decoder restarts at this one.
    if (answering_ && outstanding_ && rx_ns >= sent_ns_) {
      answering_ = false;
      time_out(answering_deadline_ns_);
    }
    reply_start_ns_ = rx_ns;
  }
  if (decoder_.decode(f) != vesc::VescDecoder::Event::kValues) {
    if (ends_reply(f)) reply_start_ns_ = 0;  // decoded and refused (CRC, length, mask): no reply is under way
    return false;
  }

  const std::int64_t t = reply_start_ns_ != 0 ? reply_start_ns_ : rx_ns;
  reply_start_ns_ = 0;
  ++reads_;
  last_read_ = {t, decoder_.values().tachometer * vesc::kTachometerStepRad};
  last_accel_change_rad_s2_ = std::nan("");
  // Which poll it answers. The second slot's, if one waits for its reply and the reply began before the poll now
  // out went out (it began in time and straddles that poll, as at 1 kHz on a 1 Mbit/s bus). Else, where a poll timed
  // out unanswered within the period, that one's if the reply began before the poll now out went out (it began after
  // its deadline) or if no poll is out. Else the outstanding poll's: a reply that began after the next poll went out
  // is later than the timeout allows, and taking it as the timed-out poll's would leave the outstanding one to time
  // out in turn, so that one lost reply would make every later reply "late" and every poll a timeout.
  const bool timed_out_pending = timed_out_unanswered_ && t - timed_out_at_ns_ <= config_.period_ns;
  const bool began_before_outstanding = t < sent_ns_;
  if (answering_ && (!outstanding_ || began_before_outstanding)) {
    answering_ = false;  // the reply that began in time: its poll is answered
    consecutive_timeouts_ = 0;
  } else if (timed_out_pending && (!outstanding_ || began_before_outstanding)) {
    ++counters_.late;
    consecutive_timeouts_ = 0;
    gap_ = gap_before_timeout_;  // the read it feared lost is this one: the chain holds
  } else if (outstanding_) {
    outstanding_ = false;
    consecutive_timeouts_ = 0;
  } else {
    ++counters_.unrequested;
  }
  timed_out_unanswered_ = false;

  const core::SpeedRead earlier_speed = earlier_speed_, previous_speed = previous_speed_;
  const bool three_reads = speeds_seen_ == 2;
  earlier_speed_ = previous_speed_;
  previous_speed_ = {t, core::rpm_to_rad_s(decoder_.values().erpm)};
  speeds_seen_ = std::min(speeds_seen_ + 1, 2);
  if (!has_window_start_) {  // the first reply only opens the first window
    has_window_start_ = true;
    window_start_ns_ = t;
    gap_ = false;
    return false;
  }
  if (!plausible_window(t)) {
    window_start_ns_ = t;  // the read reset the averages all the same
    gap_ = true;
    return false;
  }
  sample = vesc::to_averaged_sample(decoder_.values(), window_start_ns_, t);
  sample.omega_el_rad_s =
      core::window_mean_speed_rad_s(previous_speed, previous_speed_, window_start_ns_, config_.pll.ramp_lag_s());
  sample.omega_el_at_reads_max_rad_s = core::reads_speed_max_rad_s(previous_speed, previous_speed_);
  // The change of acceleration the last three replies show: SpeedErrorDelay judges the window by it and the next's.
  if (three_reads)
    last_accel_change_rad_s2_ = core::read_accel_change_rad_s2(earlier_speed, previous_speed, previous_speed_);
  sample.gap_before = gap_;
  gap_ = false;
  window_start_ns_ = t;
  ++counters_.samples;
  if (vesc::is_no_motor_reading(decoder_.values().temp_motor_C)) ++counters_.no_motor_reading;
  return true;
}

}  // namespace rpem::daemon
