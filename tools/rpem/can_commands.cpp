// rpem replay LOG.csv [--log-map MAP.yaml] --can IFACE [--rate X] [--classic] …   streams a drive log as telemetry
// rpem record --can IFACE --out LOG.csv [--duration S] …     writes received telemetry as a drive log
// rpem record --can IFACE --averaged-out AVG.csv [--signal-map MAP.yaml | --vesc-id N] …
//                                                          writes averaged rotor-frame samples (record_averaged.hpp)

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <vector>

#include "can_stream.hpp"
#include "commands.hpp"
#include "log_options.hpp"
#include "option_checks.hpp"
#include "record_averaged.hpp"
#include "rpem/can/decoder.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/log_source.hpp"

namespace rpem::tools {
namespace {

std::atomic<bool> g_can_stop{false};
void on_can_stop_signal(int) { g_can_stop = true; }

struct ReplayOptions {
  std::string log, log_map;
  StreamOptions stream;
};

int run_replay(const ReplayOptions& o) {
  if (o.stream.interface.empty() && o.stream.candump_out.empty()) {
    std::fprintf(stderr, "rpem replay: give --can IFACE and/or --candump FILE\n");
    return kExitUsage;
  }
  // Phase samples only: the telemetry carries instantaneous samples (docs/can-protocol.md), which a log of
  // averaged windows does not hold.
  const io::LogSource source = io::log_source(o.log, o.log_map);
  if (source.averaged()) {
    throw io::DriveLogError(o.log, 1, 0, "",
                            "read as " + source.format +
                                ", whose rows are averaged windows; rpem replay streams instantaneous phase samples "
                                "(a drive log, or a CSV of them through --log-map)");
  }
  io::DriveLogReader reader(o.log, source.map, {});
  TelemetryStreamer streamer(o.stream);
  io::DriveLogRow row;
  std::uint64_t n = 0;
  std::signal(SIGINT, on_can_stop_signal);
  std::signal(SIGTERM, on_can_stop_signal);
  while (!g_can_stop && reader.next(row)) {
    streamer.send(row.sample, can::protocol::status::kPwmEnabled);
    ++n;
  }
  streamer.finish();
  const can::ChannelCounters* c = streamer.channel_counters();
  std::fprintf(stderr, "rpem replay: %llu samples in %llu frames", static_cast<unsigned long long>(n),
               static_cast<unsigned long long>(streamer.frames_sent()));
  if (c) std::fprintf(stderr, ", %llu dropped by the interface", static_cast<unsigned long long>(c->tx_dropped));
  std::fprintf(stderr, "\n");
  return kExitOk;
}

int run_record(const RecordOptions& o) {
  if (!o.averaged_out.empty()) return run_record_averaged(o);
  if (o.out.empty()) {
    std::fprintf(stderr, "rpem record: give --out LOG.csv (native telemetry) or --averaged-out AVG.csv\n");
    return kExitUsage;
  }
  can::require_interface(o.interface);
  can::SocketCanChannel::Options co;
  co.interface = o.interface;
  co.ids.assign(can::protocol::kTelemetryIds.begin(), can::protocol::kTelemetryIds.end());
  can::SocketCanChannel channel(co);
  can::TelemetryDecoder decoder;
  // The temperature frame's two sensors (docs/can-protocol.md): each reading on the sample it arrived before,
  // `nan` on the rows between readings and where the drive has no such sensor (docs/drive-log.md).
  io::DriveLogLayout layout;
  layout.t_winding = true;
  layout.t_coolant = true;
  io::DriveLogWriter writer(o.out, layout);
  std::signal(SIGINT, on_can_stop_signal);
  std::signal(SIGTERM, on_can_stop_signal);
  std::fprintf(stderr, "rpem record: listening on %s\n", o.interface.c_str());

  std::vector<can::ReceivedFrame> frames(64);
  std::array<core::DriveSample, 3> samples;
  std::vector<double> latencies_us;
  std::uint64_t written = 0;
  const std::int64_t start = core::now_ns(CLOCK_MONOTONIC);
  std::int64_t last_data = start;
  while (!g_can_stop) {
    const std::int64_t now = core::now_ns(CLOCK_MONOTONIC);
    if (o.duration_s > 0 && now - start > static_cast<std::int64_t>(o.duration_s * 1e9)) break;
    if (o.idle_timeout_s > 0 && written > 0 && now - last_data > static_cast<std::int64_t>(o.idle_timeout_s * 1e9)) break;
    if (o.samples > 0 && written >= o.samples) break;
    const std::size_t n = channel.receive(frames, 100);
    const std::int64_t received_ns = core::now_ns(CLOCK_REALTIME);
    for (std::size_t f = 0; f < n; ++f) {
      const std::size_t got = decoder.decode(frames[f].frame, can::receive_time_ns(frames[f], received_ns), samples);
      if (got > 0) last_data = core::now_ns(CLOCK_MONOTONIC);
      for (std::size_t k = 0; k < got; ++k) {
        writer.write({samples[k], {}, {}});
        ++written;
      }
      if (o.latency && got > 0 && frames[f].kernel_rx_ns > 0) {
        // The protocol carries the drive time modulo 2^32 µs: compare the receive time modulo that too.
        const auto rx_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(frames[f].kernel_rx_ns / 1000));
        const auto tx_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(samples[got - 1].t_ns / 1000));
        latencies_us.push_back(static_cast<double>(static_cast<std::int32_t>(rx_us - tx_us)));
      }
    }
  }
  writer.flush();
  const auto& d = decoder.counters();
  const auto& c = channel.counters();
  std::fprintf(stderr,
               "rpem record: %llu samples written to %s\n"
               "  frames %llu, gaps %llu, lost %llu, duplicated %llu, reordered %llu, crc %llu, wrong dlc %llu, "
               "unknown id %llu, stale %llu, out of range %llu, invalid %llu, incomplete %llu\n"
               "  kernel drops %llu, reopens %llu, error frames %llu (bus-off %llu, error-passive %llu)\n",
               static_cast<unsigned long long>(written), o.out.c_str(), static_cast<unsigned long long>(d.frames),
               static_cast<unsigned long long>(d.gaps), static_cast<unsigned long long>(d.frames_lost),
               static_cast<unsigned long long>(d.duplicated), static_cast<unsigned long long>(d.reordered),
               static_cast<unsigned long long>(d.crc_error), static_cast<unsigned long long>(d.wrong_dlc),
               static_cast<unsigned long long>(d.unknown_id), static_cast<unsigned long long>(d.stale),
               static_cast<unsigned long long>(d.out_of_range), static_cast<unsigned long long>(d.invalid_value),
               static_cast<unsigned long long>(d.incomplete), static_cast<unsigned long long>(c.kernel_drops),
               static_cast<unsigned long long>(c.reopens), static_cast<unsigned long long>(c.error_frames),
               static_cast<unsigned long long>(c.bus_off), static_cast<unsigned long long>(c.error_passive));
  if (o.latency && !latencies_us.empty()) {
    std::sort(latencies_us.begin(), latencies_us.end());
    auto pct = [&](double q) {
      return latencies_us[static_cast<std::size_t>(q * static_cast<double>(latencies_us.size() - 1))];
    };
    std::fprintf(
        stderr,
        "  latency, scheduled time of a frame's last sample -> kernel receive [us]: p50 %.1f, p99 %.1f, max %.1f (%zu frames)\n",
        pct(0.5), pct(0.99), latencies_us.back(), latencies_us.size());
  }
  return kExitOk;
}

}  // namespace

Runner add_replay_command(CLI::App& app) {
  auto opts = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand("replay", "Stream a drive log as rpem telemetry on a CAN interface");
  cmd->add_option("log", opts->log, "drive log (phase samples), or a CSV of them with --log-map (docs/drive-log.md)")
      ->required()
      ->check(CLI::ExistingFile);
  add_log_map_option(*cmd, opts->log_map);
  cmd->add_option("--can", opts->stream.interface, "SocketCAN interface (e.g. vcan0)");
  add_stream_options(cmd, opts->stream);
  return [cmd, opts]() { return cmd->parsed() ? run_replay(*opts) : -1; };
}

Runner add_record_command(CLI::App& app) {
  auto opts = std::make_shared<RecordOptions>();
  CLI::App* cmd = app.add_subcommand("record", "Write what a drive sends on CAN as a drive log or an averaged log");
  cmd->add_option("--can", opts->interface, "SocketCAN interface")->required();
  writes_file(cmd->add_option("--out", opts->out, "drive-log CSV to write (rpem's native telemetry, phase samples)"));
  writes_file(cmd->add_option(
                  "--averaged-out", opts->averaged_out,
                  "averaged rotor-frame log to write (docs/drive-log.md): from --signal-map, --vesc-id or native telemetry"))
      ->excludes("--out");
  cmd->add_option("--signal-map", opts->signal_map, "read the drive's own frames through this map (docs/sources.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--vesc-id", opts->vesc_id, "poll this VESC (controller id) with COMM_GET_VALUES_SELECTIVE")
      ->check(CLI::Range(0, 254))
      ->excludes("--signal-map");
  cmd->add_option("--host-id", opts->host_id, "VESC: the id replies are addressed to (no VESC may use it)")
      ->check(CLI::Range(0, 254));
  cmd->add_option("--poll-rate", opts->poll_rate_Hz, "VESC: polls per second")->check(CLI::Range(1.0, 2000.0));
  cmd->add_option("--window-rate", opts->window_rate_Hz, "native telemetry: averaging windows per second")
      ->check(CLI::Range(50.0, 2000.0));
  cmd->add_option("--duration", opts->duration_s, "stop after this many seconds");
  cmd->add_option("--samples", opts->samples, "stop after this many samples");
  cmd->add_option("--idle-timeout", opts->idle_timeout_s, "stop when no sample arrived for this long (after the first)");
  cmd->add_flag("--latency", opts->latency, "report drive-sample to kernel-receive latency (sender used --wall-timestamps)");
  return [cmd, opts]() { return cmd->parsed() ? run_record(*opts) : -1; };
}

}  // namespace rpem::tools
