#include "rpem/daemon/vesc_source.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <memory>
#include <optional>

#include "rpem/can/socketcan.hpp"
#include "rpem/can/vesc.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/count_delay.hpp"
#include "rpem/daemon/socketcan_source.hpp"
#include "rpem/daemon/speed_error_delay.hpp"
#include "rpem/daemon/vesc_poller.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;
using can::vesc::VescCounters;

constexpr std::array<CounterRow<VescPollerCounters, std::uint64_t>, 11> kPollerRows{{
    {&VescPollerCounters::polls, &Diag::vesc_polls},
    {&VescPollerCounters::send_failures, &Diag::vesc_send_failures},
    {&VescPollerCounters::samples, &Diag::vesc_replies},
    {&VescPollerCounters::timeouts, &Diag::vesc_timeouts},
    {&VescPollerCounters::late, &Diag::vesc_late_replies},
    {&VescPollerCounters::unrequested, &Diag::vesc_unrequested_replies},
    {&VescPollerCounters::stolen_reads, &Diag::vesc_stolen_reads},
    {&VescPollerCounters::short_windows, &Diag::vesc_short_windows},
    {&VescPollerCounters::empty_reads, &Diag::vesc_empty_reads},
    {&VescPollerCounters::long_windows, &Diag::vesc_long_windows},
    {&VescPollerCounters::no_motor_reading, &Diag::temperature_no_reading},
}};
constexpr std::array<CounterRow<VescCounters, std::uint64_t>, 7> kVescDecoderRows{{
    {&VescCounters::frames, &Diag::can_frames},
    {&VescCounters::foreign, &Diag::can_foreign},
    {&VescCounters::unknown_packet, &Diag::can_unknown_id},
    {&VescCounters::wrong_length, &Diag::can_wrong_dlc},
    {&VescCounters::crc_error, &Diag::can_crc_error},
    {&VescCounters::short_reply, &Diag::vesc_short_replies},
    {&VescCounters::statuses, &Diag::vesc_statuses},
}};
static_assert(kPollerRows.size() + kVescDecoderRows.size() + kChannelRows.size() + 3 <= DiagnosticsRows::kMaxCounts);

}  // namespace

VescPoller::Config poller_config(const VescSource::Options& o) noexcept {
  VescPoller::Config c;
  c.controller_id = static_cast<std::uint8_t>(o.controller_id);
  c.host_id = static_cast<std::uint8_t>(o.host_id);
  c.period_ns = std::llround(1e9 / o.poll_rate_Hz);
  c.phase_ns = std::llround(o.poll_phase * static_cast<double>(c.period_ns));
  c.timeout_ns =
      std::min<std::int64_t>(c.period_ns, std::llround(o.reply_timeout_s * 1e9));  // ≤ the period, as parsed, to the ns
  c.pll = {o.pll_kp, o.pll_ki};
  c.mask = o.count_horizon_s > 0.0 ? can::vesc::kCountingMask : can::vesc::kEstimatorMask;
  return c;
}

std::int64_t reply_gather_ns(std::int64_t poll_period_ns) noexcept {
  return std::min<std::int64_t>(1'000'000, poll_period_ns / 16);
}

void report_vesc_counters(const VescPoller& poller, DiagnosticsRows& rows) noexcept {
  rows.set_all(kPollerRows, poller.counters());
  const VescCounters& d = poller.decoder().counters();
  rows.set_all(kVescDecoderRows, d);
  rows.set(&Diag::vesc_buffer_errors, static_cast<std::int64_t>(d.out_of_order + d.overflow + d.length_mismatch));
  rows.set(&Diag::vesc_bad_replies, static_cast<std::int64_t>(d.not_values + d.trailing + d.wrong_mask));
}

namespace {

class VescSampleSource final : public SampleSource {
 public:
  explicit VescSampleSource(VescSource::Options o) : options_(std::move(o)) {}

  void run(const std::atomic<bool>& stop, SourceOutput& out) override {
    can::SocketCanChannel::Options o;
    o.interface = options_.interface;
    o.fd = false;
    // The kernel passes what the poller reads: replies to us, the controller's statuses, and other nodes'
    // commands to it or to all (stolen averages); the rest of the bus stays in the kernel.
    const auto filters = can::vesc::kernel_filters(static_cast<std::uint8_t>(options_.controller_id),
                                                   static_cast<std::uint8_t>(options_.host_id));
    o.filters.assign(filters.begin(), filters.end());
    can::SocketCanChannel channel(o);
    ChannelNotices notices;
    VescPoller poller(poller_config(options_));
    std::array<can::ReceivedFrame, 64> frames;
    core::AveragedSample sample;
    // Each window waits for the next reply, which shows whether its speed's rebuild holds (SpeedErrorDelay); counting,
    // then for the reads after it (CountDelay; allocated once, here: the loop below allocates nothing).
    SpeedErrorDelay speed_error(poller_config(options_).pll);
    const bool counting = options_.count_horizon_s > 0.0;
    const auto delay = counting ? std::make_unique<CountDelay>(can::vesc::kTachometerStepRad, options_.count_horizon_s)
                                : std::unique_ptr<CountDelay>();
    const std::int64_t gather_ns = reply_gather_ns(poller_config(options_).period_ns);
    const timespec gather{0, static_cast<long>(gather_ns)};
    // Takes n received frames (their kernel receive times; `now` where a frame has none); true if one completed a
    // reply that became a sample.
    auto take = [&](std::size_t n, std::int64_t now) {
      bool completed = false;
      for (std::size_t f = 0; f < n; ++f) {
        const std::uint64_t reads_before = poller.reads();
        const bool sampled = poller.on_frame(frames[f].frame, receive_time_ns(frames[f], now), sample);
        completed = completed || sampled;
        if (poller.reads() == reads_before) continue;
        // A reply: the window held is judged and goes on — to CountDelay before this read, which ends no window of
        // its yet (add_window takes a window ending at its newest read).
        core::AveragedSample due;
        if (speed_error.on_read(poller.last_accel_change_rad_s2(), due)) {
          if (!counting) {
            out.push(due);
          } else {
            for (core::AveragedSample early; delay->full() && delay->release(now, early);) out.push(early);
            delay->add_window(due);
          }
        }
        if (counting) delay->add_read(poller.last_read());
        if (sampled) speed_error.hold(sample);
      }
      return completed;
    };
    std::int64_t wait_ns = 0;
    while (!stop.load(std::memory_order_relaxed)) {
      const std::size_t n = channel.receive_for(frames, wait_ns);
      // The poll schedule and the windows run on CLOCK_REALTIME, the kernel's receive timestamps' clock.
      const std::int64_t now = core::now_ns(CLOCK_REALTIME);
      bool completed = take(n, now);
      std::size_t received = n;
      // Every frame the kernel received by `now` is taken before a deadline is judged at `now`: a reply that came in
      // time is not timed out because this thread ran late (a host that held it off the CPU past the deadline).
      for (std::size_t more = 1; more > 0; received += more) {
        more = channel.receive_for(frames, 0);
        completed = take(more, now) || completed;
      }
      poller.on_time(now);
      if (poller.poll_due(now)) poller.polled(now, channel.send(poller.poll_frame(), 0));
      wait_ns = std::clamp<std::int64_t>(poller.wake_ns(now) - now, 0, 50'000'000);
      if (counting) {
        for (core::AveragedSample due; delay->release(now, due);) out.push(due);
      }
      // Frames but no complete reply: the rest of it is on its way — take it in one wake-up, not one per frame.
      if (received > 0 && !completed) {
        nanosleep(&gather, nullptr);
        wait_ns = std::max<std::int64_t>(0, wait_ns - gather_ns);
      }
      report_when_due(out, channel, notices, options_.interface,
                      [&](DiagnosticsRows& rows) { report_vesc_counters(poller, rows); });
    }
  }
  [[nodiscard]] std::string name() const override {
    return options_.interface + " controller " + std::to_string(options_.controller_id);
  }

 private:
  VescSource::Options options_;
};

}  // namespace

VescSource::Options VescSource::parse(io::YamlMap& section, const std::string&) {
  Options o;
  o.interface = parse_interface(section);
  o.controller_id = static_cast<int>(section.integer("controller_id", 0, 254));
  o.host_id = static_cast<int>(section.integer_or("host_id", o.host_id, 0, 254));
  if (o.host_id == o.controller_id) section.fail("host_id", "must differ from controller_id (replies are addressed to it)");
  o.poll_rate_Hz = section.number_or("poll_rate_Hz", o.poll_rate_Hz, 1.0, 2000.0);
  o.poll_phase = section.number_or("poll_phase", o.poll_phase, 0.0, 0.999);
  const double period_s = 1.0 / o.poll_rate_Hz;
  o.reply_timeout_s = section.number_or("reply_timeout_s", std::min(0.9 * period_s, 20e-3), 1e-4, period_s);
  if (std::optional<io::YamlMap> pll = section.optional_map("pll")) {
    o.pll_kp = pll->number_or("kp", o.pll_kp, 1e-3, 1e7);
    o.pll_ki = pll->number_or("ki", o.pll_ki, 1e-3, 1e10);
    pll->finish();
  }
  section.finish();
  return o;
}

std::unique_ptr<SampleSource> VescSource::make(const Options& options) {
  return std::make_unique<VescSampleSource>(options);
}

}  // namespace rpem::daemon
