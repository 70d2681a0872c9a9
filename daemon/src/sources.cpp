#include "rpem/daemon/sources.hpp"

#include <ctime>
#include <vector>

#include "rpem/can/decoder.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/can/socketcan.hpp"
#include "rpem/daemon/realtime.hpp"
#include "rpem/sim/drive_simulator.hpp"

namespace rpem::daemon {
namespace {

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until(std::int64_t t_ns) {
  timespec ts{static_cast<time_t>(t_ns / 1'000'000'000), static_cast<long>(t_ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void push(SpscQueue<core::DriveSample>& q, const core::DriveSample& s, SourceStats& stats) {
  if (q.push(s)) {
    stats.samples.fetch_add(1, std::memory_order_relaxed);
  } else {
    stats.queue_drops.fetch_add(1, std::memory_order_relaxed);
  }
}

class CanSource final : public SampleSource {
 public:
  CanSource(const DaemonConfig& c, SpscQueue<core::DriveSample>& out, SourceStats& stats)
      : config_(c), out_(out), stats_(stats) {}
  ~CanSource() override { join(); }

  void start(std::atomic<bool>& stop) override {
    thread_ = std::thread([this, &stop] { run(stop); });
  }
  void join() override {
    if (thread_.joinable()) thread_.join();
  }
  [[nodiscard]] std::string name() const override { return config_.can_interface; }

 private:
  void run(std::atomic<bool>& stop) {
    name_thread("rpemd-can-rx");
    (void)apply_thread_policy(config_.realtime == RealtimeMode::kOff ? ThreadPolicy{} : config_.receive_thread);
    can::SocketCanChannel::Options o;
    o.interface = config_.can_interface;
    o.ids = {can::protocol::kFdId};
    for (int k = 0; k < can::protocol::kClassicFrames; ++k) o.ids.push_back(can::protocol::kClassicFirstId + static_cast<std::uint32_t>(k));
    can::SocketCanChannel channel(o);
    can::TelemetryDecoder decoder;
    std::vector<can::ReceivedFrame> frames(64);
    std::array<core::DriveSample, 3> samples;
    bool was_open = channel.is_open();
    while (!stop.load(std::memory_order_relaxed)) {
      const std::size_t n = channel.receive(frames, 50);
      if (channel.is_open() != was_open) {
        was_open = channel.is_open();
        if (!was_open) decoder.resynchronize();  // whatever arrives after the outage starts a new stream
      }
      for (std::size_t f = 0; f < n; ++f) {
        const std::size_t got = decoder.decode(frames[f].frame, samples);
        for (std::size_t k = 0; k < got; ++k) {
          samples[k].rx_ns = frames[f].kernel_rx_ns;
          push(out_, samples[k], stats_);
        }
      }
      publish(decoder.counters(), channel.counters());
    }
  }

  void publish(const can::DecoderCounters& d, const can::ChannelCounters& c) {
    auto set = [](std::atomic<std::int64_t>& a, std::uint64_t v) { a.store(static_cast<std::int64_t>(v), std::memory_order_relaxed); };
    set(stats_.frames, d.frames);
    set(stats_.unknown_id, d.unknown_id);
    set(stats_.wrong_dlc, d.wrong_dlc);
    set(stats_.bad_version, d.bad_version);
    set(stats_.crc_error, d.crc_error);
    set(stats_.frames_lost, d.frames_lost);
    set(stats_.duplicated, d.duplicated);
    set(stats_.reordered, d.reordered);
    set(stats_.stale, d.stale);
    set(stats_.out_of_range, d.out_of_range);
    set(stats_.invalid_value, d.invalid_value);
    set(stats_.incomplete, d.incomplete);
    set(stats_.gaps, d.gaps);
    set(stats_.kernel_drops, c.kernel_drops);
    set(stats_.reopens, c.reopens);
    set(stats_.error_frames, c.error_frames);
    set(stats_.bus_off, c.bus_off);
    set(stats_.error_passive, c.error_passive);
    set(stats_.controller_overflow, c.controller_overflow);
  }

  const DaemonConfig& config_;
  SpscQueue<core::DriveSample>& out_;
  SourceStats& stats_;
  std::thread thread_;
};

sim::Scenario load_demo_or_file(const std::string& spec) {
  if (spec == "builtin:rpemd-demo") return sim::parse_scenario(builtin_demo_scenario_text(), "<built-in rpemd-demo>", "");
  return sim::load_scenario(spec);
}

class SimSource final : public SampleSource {
 public:
  SimSource(const DaemonConfig& c, SpscQueue<core::DriveSample>& out, SourceStats& stats)
      : config_(c), out_(out), stats_(stats), scenario_(load_demo_or_file(c.sim_scenario)) {
    stats_.simulated = true;
  }
  ~SimSource() override { join(); }

  void start(std::atomic<bool>& stop) override {
    thread_ = std::thread([this, &stop] { run(stop); });
  }
  void join() override {
    if (thread_.joinable()) thread_.join();
  }
  [[nodiscard]] std::string name() const override { return scenario_.name; }

 private:
  void run(std::atomic<bool>& stop) {
    name_thread("rpemd-sim");
    (void)apply_thread_policy(config_.realtime == RealtimeMode::kOff ? ThreadPolicy{} : config_.receive_thread);
    // The drive produces its samples in 1 ms batches, in step with the wall clock: every sample whose
    // drive time has passed is pushed. On restart (loop) the drive time carries on.
    constexpr std::int64_t kBatchNs = 1'000'000;
    auto drive = std::make_unique<sim::DriveSimulator>(scenario_);
    const std::int64_t wall_start = monotonic_ns();
    std::int64_t target = wall_start;
    std::int64_t offset_ns = 0;
    std::int64_t last_t = 0;
    io::DriveLogRow row;
    sim::TruthRow truth;
    bool have_row = false;
    while (!stop.load(std::memory_order_relaxed)) {
      target += kBatchNs;
      sleep_until(target);
      const std::int64_t elapsed = target - wall_start;
      while (true) {
        if (!have_row) {
          if (!drive->next(row, truth)) {
            if (!config_.sim_loop) return;
            offset_ns = last_t + drive->period_ns();
            drive = std::make_unique<sim::DriveSimulator>(scenario_);
            continue;
          }
          row.sample.t_ns += offset_ns;
          have_row = true;
        }
        if (row.sample.t_ns > elapsed) break;
        push(out_, row.sample, stats_);
        stats_.truth_psi_m_Wb.store(truth.parameters.psi_m_Wb, std::memory_order_relaxed);
        stats_.truth_r_s_Ohm.store(truth.parameters.r_s_Ohm, std::memory_order_relaxed);
        last_t = row.sample.t_ns;
        have_row = false;
      }
    }
  }

  const DaemonConfig& config_;
  SpscQueue<core::DriveSample>& out_;
  SourceStats& stats_;
  sim::Scenario scenario_;
  std::thread thread_;
};

}  // namespace

std::unique_ptr<SampleSource> make_source(const DaemonConfig& config, SpscQueue<core::DriveSample>& out,
                                          SourceStats& stats) {
  if (config.source == SourceType::kCan) return std::make_unique<CanSource>(config, out, stats);
  return std::make_unique<SimSource>(config, out, stats);
}

}  // namespace rpem::daemon
