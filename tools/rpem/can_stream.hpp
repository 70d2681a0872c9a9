#pragma once
// Streams drive samples as telemetry: paced in (scaled) real time onto a SocketCAN interface, and/or
// written as a `candump -L` log. Shared by `rpem sim --can` and `rpem replay`.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "rpem/can/encoder.hpp"
#include "rpem/can/socketcan.hpp"

namespace rpem::tools {

struct StreamOptions {
  std::string interface;          ///< SocketCAN interface; empty: none
  std::string candump_out;        ///< candump -L file; empty: none
  double rate = 1.0;              ///< 1: real time, 2: twice as fast, 0: as fast as possible
  bool classic = false;           ///< classic CAN mapping (five frames per sample)
  int samples_per_frame = 3;      ///< CAN FD
  bool wall_timestamps = false;   ///< stamp samples with their scheduled CLOCK_REALTIME time (latency tests)
  double drop_probability = 0.0;  ///< test aid: drop frames at random with this probability…
  int drop_burst = 1;             ///< …each loss taking this many consecutive frames
  std::uint64_t drop_seed = 1;
};

/// The options shared by every streaming subcommand (--rate, --classic, --samples-per-frame, …).
void add_stream_options(CLI::App* cmd, StreamOptions& options);

class TelemetryStreamer {
 public:
  explicit TelemetryStreamer(const StreamOptions& options);
  ~TelemetryStreamer();

  /// Waits for the sample's time, encodes it and sends what the encoder completes.
  void send(core::DriveSample sample, std::uint8_t status);
  /// Sends a partial frame.
  void finish();

  [[nodiscard]] std::uint64_t frames_sent() const noexcept { return frames_; }
  [[nodiscard]] std::uint64_t frames_dropped() const noexcept { return dropped_; }
  /// How far behind schedule the frames left (percentiles), for latency measurements.
  [[nodiscard]] std::string lateness_summary() const;
  [[nodiscard]] const can::ChannelCounters* channel_counters() const;

 private:
  void emit(const can::CanFrame& f);

  StreamOptions options_;
  can::TelemetryEncoder encoder_;
  std::unique_ptr<can::SocketCanChannel> channel_;
  std::ofstream candump_;
  bool started_ = false;
  std::int64_t first_t_ns_ = 0;
  std::int64_t start_mono_ns_ = 0;
  std::int64_t start_real_ns_ = 0;
  std::int64_t last_real_ns_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t dropped_ = 0;
  int burst_left_ = 0;
  std::uint64_t rng_state_;
  std::vector<double> lateness_us_;
};

}  // namespace rpem::tools
