#include "record_averaged.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <memory>
#include <vector>

#include "commands.hpp"
#include "rpem/can/decoder.hpp"
#include "rpem/can/signal_map.hpp"
#include "rpem/can/socketcan.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/vesc_poller.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/signal_map_config.hpp"
#include "rpem/sim/cycle_average.hpp"

namespace rpem::tools {
namespace {

std::atomic<bool> g_record_stop{false};
void on_record_stop_signal(int) { g_record_stop = true; }

/// One source of averaged samples on a CAN channel.
class Feed {
 public:
  virtual ~Feed() = default;
  /// Called at least every millisecond (a poller sends here).
  virtual void on_time(std::int64_t /*now_ns*/, can::SocketCanChannel& /*channel*/) {}
  /// One received frame with its receive time (kernel stamp, CLOCK_REALTIME); true when `out` holds a sample.
  virtual bool on_frame(const can::ReceivedFrame& f, std::int64_t rx_ns, core::AveragedSample& out) = 0;
  [[nodiscard]] virtual std::string summary() const = 0;
  /// Which optional columns the log gets.
  [[nodiscard]] virtual io::AveragedLogLayout layout() const = 0;
};

/// rpem's native telemetry: phase samples, averaged in the rotor frame over windows of 1/rate (the cycle
/// means of sim/cycle_average.hpp: measured current at each sample's angle, the held voltage's
/// rotor-frame mean over its period).
class NativeFeed final : public Feed {
 public:
  explicit NativeFeed(double window_rate_Hz) : windows_(window_rate_Hz, 0.0, 1) {}
  bool on_frame(const can::ReceivedFrame& f, std::int64_t rx_ns, core::AveragedSample& out) override {
    const std::size_t n = decoder_.decode(f.frame, rx_ns, samples_);
    bool got = false;
    for (std::size_t k = 0; k < n; ++k) {
      if (const auto cycle = cycles_.add(io::DriveLogRow{samples_[k], {}, {}})) {
        if (const auto w = windows_.add(*cycle)) {
          out = *w;
          got = true;  // windows are ≥ 0.5 ms, a frame carries ≤ 3 samples: at most one per frame
        }
      }
    }
    return got;
  }
  [[nodiscard]] std::string summary() const override {
    const auto& d = decoder_.counters();
    return "native telemetry: frames " + std::to_string(d.frames) + ", gaps " + std::to_string(d.gaps) + ", lost " +
           std::to_string(d.frames_lost) + ", crc " + std::to_string(d.crc_error) + ", unknown id " +
           std::to_string(d.unknown_id);
  }
  /// The temperature frame's two sensors: each window the mean of the readings in it (sim/cycle_average.hpp).
  [[nodiscard]] io::AveragedLogLayout layout() const override {
    io::AveragedLogLayout l;
    l.u_dc = l.t_winding = l.t_coolant = true;
    return l;
  }

 private:
  can::TelemetryDecoder decoder_;
  std::array<core::DriveSample, 3> samples_;
  sim::CycleExtractor cycles_;
  sim::WindowAverager windows_;
};

/// A drive's own frames through a signal map (docs/sources.md); the sample's time is the trigger frame's
/// receive time.
class SignalMapFeed final : public Feed {
 public:
  explicit SignalMapFeed(can::SignalMap map) : decoder_(std::move(map)) {}
  bool on_frame(const can::ReceivedFrame& f, std::int64_t rx_ns, core::AveragedSample& out) override {
    return decoder_.decode(f.frame, rx_ns, out);
  }
  [[nodiscard]] std::string summary() const override {
    const auto& c = decoder_.counters();
    return "signal map '" + decoder_.map().name + "': frames " + std::to_string(c.frames) + ", samples " +
           std::to_string(c.samples) + ", unknown id " + std::to_string(c.unknown_id) + ", wrong length " +
           std::to_string(c.wrong_length) + ", incomplete " + std::to_string(c.incomplete) + ", non-finite " +
           std::to_string(c.non_finite) + ", stale " + std::to_string(c.stale);
  }
  /// Every temperature the map has a signal for (a sample without its reading writes nan).
  [[nodiscard]] io::AveragedLogLayout layout() const override {
    const can::SignalMap& m = decoder_.map();
    io::AveragedLogLayout l;
    l.u_dc = true;
    l.t_winding = can::maps_field(m, can::SampleField::kTWindingC);
    l.t_magnet = can::maps_field(m, can::SampleField::kTMagnetC);
    l.t_drive = can::maps_field(m, can::SampleField::kTDriveC);
    l.t_coolant = can::maps_field(m, can::SampleField::kTCoolantC);
    return l;
  }

 private:
  can::SignalMapDecoder decoder_;
};

/// A VESC polled with COMM_GET_VALUES_SELECTIVE: rpemd's own poller (daemon/vesc_poller.hpp — schedule,
/// timeouts, windows from read to read, stolen reads), so that a recorded log holds what rpemd estimates from.
class VescFeed final : public Feed {
 public:
  explicit VescFeed(const daemon::VescPoller::Config& c) : poller_(c) {}
  void on_time(std::int64_t now_ns, can::SocketCanChannel& channel) override {
    poller_.on_time(now_ns);
    if (poller_.poll_due(now_ns)) poller_.polled(now_ns, channel.send(poller_.poll_frame(), 0));
  }
  bool on_frame(const can::ReceivedFrame& f, std::int64_t rx_ns, core::AveragedSample& out) override {
    return poller_.on_frame(f.frame, rx_ns, out);
  }
  [[nodiscard]] std::string summary() const override {
    const auto& c = poller_.counters();
    return "VESC: polls " + std::to_string(c.polls) + ", windows " + std::to_string(c.samples) + ", timeouts " +
           std::to_string(c.timeouts) + ", late " + std::to_string(c.late) + ", unrequested " +
           std::to_string(c.unrequested) + ", stolen reads " + std::to_string(c.stolen_reads) + ", short windows " +
           std::to_string(c.short_windows) + ", empty reads " + std::to_string(c.empty_reads) + ", long windows " +
           std::to_string(c.long_windows) + ", send failures " + std::to_string(c.send_failures) +
           ", no motor temperature " + std::to_string(c.no_motor_reading);
  }
  [[nodiscard]] io::AveragedLogLayout layout() const override { return {true, true, false, true}; }

 private:
  daemon::VescPoller poller_;
};

std::unique_ptr<Feed> make_feed(const RecordOptions& o) {
  if (!o.signal_map.empty()) return std::make_unique<SignalMapFeed>(io::load_signal_map(o.signal_map));
  if (o.vesc_id >= 0) {
    daemon::VescPoller::Config c;
    c.controller_id = static_cast<std::uint8_t>(o.vesc_id);
    c.host_id = static_cast<std::uint8_t>(o.host_id);
    c.period_ns = static_cast<std::int64_t>(1e9 / o.poll_rate_Hz);
    c.timeout_ns = std::min<std::int64_t>(c.period_ns / 2, 5'000'000);  // as rpemd's default reply_timeout_s
    return std::make_unique<VescFeed>(c);
  }
  return std::make_unique<NativeFeed>(o.window_rate_Hz);
}

}  // namespace

int run_record_averaged(const RecordOptions& o) {
  std::unique_ptr<Feed> feed = make_feed(o);
  can::require_interface(o.interface);
  can::SocketCanChannel::Options co;
  co.interface = o.interface;
  can::SocketCanChannel channel(co);
  io::AveragedLogWriter writer(o.averaged_out, feed->layout());
  std::signal(SIGINT, on_record_stop_signal);
  std::signal(SIGTERM, on_record_stop_signal);
  std::fprintf(stderr, "rpem record: listening on %s, writing averaged samples to %s\n", o.interface.c_str(),
               o.averaged_out.c_str());
  std::vector<can::ReceivedFrame> frames(64);
  std::uint64_t written = 0;
  const std::int64_t start = core::now_ns(CLOCK_MONOTONIC);
  std::int64_t last_data = start;
  core::AveragedSample sample;
  std::int64_t origin_ns = 0;
  auto take = [&](std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) {
      const std::int64_t rx = can::receive_time_ns(frames[k], core::now_ns(CLOCK_REALTIME));
      if (!feed->on_frame(frames[k], rx, sample)) continue;
      // The log's time starts at 0 with the first window (host CLOCK_REALTIME or drive time before).
      if (written == 0) origin_ns = sample.t_start_ns;
      sample.t_start_ns -= origin_ns;
      sample.t_ns -= origin_ns;
      writer.write(sample);
      ++written;
      last_data = core::now_ns(CLOCK_MONOTONIC);
    }
  };
  while (!g_record_stop) {
    const std::int64_t now = core::now_ns(CLOCK_MONOTONIC);
    if (o.duration_s > 0 && now - start > static_cast<std::int64_t>(o.duration_s * 1e9)) break;
    if (o.idle_timeout_s > 0 && written > 0 && now - last_data > static_cast<std::int64_t>(o.idle_timeout_s * 1e9)) break;
    if (o.samples > 0 && written >= o.samples) break;
    take(channel.receive(frames, 1));
    // Every frame the kernel received by `now_rt` is taken before the feed judges a deadline at it (as rpemd's VESC
    // source: a reply that came in time is not timed out because this process ran late).
    const std::int64_t now_rt = core::now_ns(CLOCK_REALTIME);
    for (std::size_t more = 1; more > 0;) {
      more = channel.receive_for(frames, 0);
      take(more);
    }
    feed->on_time(now_rt, channel);
  }
  writer.flush();
  const auto& c = channel.counters();
  std::fprintf(
      stderr,
      "rpem record: %llu averaged samples written to %s\n  %s\n  kernel drops %llu, reopens %llu, error frames %llu\n",
      static_cast<unsigned long long>(written), o.averaged_out.c_str(), feed->summary().c_str(),
      static_cast<unsigned long long>(c.kernel_drops), static_cast<unsigned long long>(c.reopens),
      static_cast<unsigned long long>(c.error_frames));
  return kExitOk;
}

}  // namespace rpem::tools
