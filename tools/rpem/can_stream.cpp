#include "can_stream.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <ctime>

#include "rpem/core/clock.hpp"

namespace rpem::tools {
using core::now_ns;

void add_stream_options(CLI::App* cmd, StreamOptions& o) {
  cmd->add_option("--rate", o.rate, "playback speed: 1 real time, 0 as fast as possible")->check(CLI::NonNegativeNumber);
  cmd->add_flag("--classic", o.classic, "classic CAN mapping (five 8-byte frames per sample)");
  cmd->add_option("--samples-per-frame", o.samples_per_frame, "samples per CAN FD frame")->check(CLI::Range(1, 3));
  cmd->add_flag("--wall-timestamps", o.wall_timestamps,
                "stamp samples with their scheduled wall-clock time (latency tests)");
  cmd->add_option("--candump", o.candump_out, "also write the frames as a candump -L log");
  cmd->add_option("--drop-probability", o.drop_probability, "test aid: drop this fraction of losses at random")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--drop-burst", o.drop_burst, "test aid: frames lost per loss event")->check(CLI::Range(1, 1000));
  cmd->add_option("--drop-seed", o.drop_seed, "test aid: seed of the loss pattern");
}

TelemetryStreamer::TelemetryStreamer(const StreamOptions& options)
    : options_(options),
      encoder_(options.classic ? can::BusMode::kClassic : can::BusMode::kFd, options.samples_per_frame),
      rng_state_(options.drop_seed * 0x9E3779B97F4A7C15ULL + 1) {
  if (!options_.interface.empty()) {
    can::require_interface(options_.interface);
    can::SocketCanChannel::Options o;
    o.interface = options_.interface;
    o.fd = !options_.classic;
    o.receive = false;
    o.receive_errors = false;
    channel_ = std::make_unique<can::SocketCanChannel>(o);
  }
  if (!options_.candump_out.empty()) {
    candump_.open(options_.candump_out, std::ios::trunc);
    if (!candump_) throw std::runtime_error("cannot create " + options_.candump_out);
  }
}

TelemetryStreamer::~TelemetryStreamer() = default;

const can::ChannelCounters* TelemetryStreamer::channel_counters() const {
  return channel_ ? &channel_->counters() : nullptr;
}

void TelemetryStreamer::emit(const can::CanFrame& f) {
  if (options_.drop_probability > 0.0) {
    // xorshift64*: a loss starts with the given probability per frame and lasts drop_burst frames.
    rng_state_ ^= rng_state_ >> 12;
    rng_state_ ^= rng_state_ << 25;
    rng_state_ ^= rng_state_ >> 27;
    const double u = static_cast<double>((rng_state_ * 0x2545F4914F6CDD1DULL) >> 11) * 0x1.0p-53;
    if (burst_left_ == 0 && u < options_.drop_probability / options_.drop_burst) burst_left_ = options_.drop_burst;
    if (burst_left_ > 0) {
      --burst_left_;
      ++dropped_;
      return;
    }
  }
  ++frames_;
  if (channel_) (void)channel_->send(f, 50);
  if (candump_.is_open()) {
    const std::int64_t t = last_real_ns_ != 0 ? last_real_ns_ : now_ns(CLOCK_REALTIME);
    char head[64];
    std::snprintf(head, sizeof head, "(%lld.%06lld) %s %03X%s", static_cast<long long>(t / 1'000'000'000),
                  static_cast<long long>((t % 1'000'000'000) / 1000),
                  options_.interface.empty() ? "can0" : options_.interface.c_str(), f.id, f.fd ? "##1" : "#");
    std::string line = head;
    char hex[3];
    for (int k = 0; k < f.len; ++k) {
      std::snprintf(hex, sizeof hex, "%02X", f.data[static_cast<std::size_t>(k)]);
      line += hex;
    }
    candump_ << line << '\n';
  }
}

void TelemetryStreamer::send(core::DriveSample sample, std::uint8_t status) {
  if (!started_) {
    started_ = true;
    first_t_ns_ = sample.t_ns;
    start_mono_ns_ = now_ns(CLOCK_MONOTONIC);
    start_real_ns_ = now_ns(CLOCK_REALTIME);
  }
  const std::int64_t offset_ns = sample.t_ns - first_t_ns_;
  const std::int64_t scheduled =
      options_.rate > 0.0 ? static_cast<std::int64_t>(static_cast<double>(offset_ns) / options_.rate) : offset_ns;
  last_real_ns_ = start_real_ns_ + scheduled;
  if (options_.wall_timestamps) sample.t_ns = last_real_ns_;
  std::array<can::CanFrame, can::TelemetryEncoder::kMaxFramesPerAdd> frames;
  const std::size_t n = encoder_.add(sample, status, frames);
  // A frame leaves when its last sample is due (one wake-up per frame, not per sample).
  if (n > 0 && options_.rate > 0.0) {
    const std::int64_t due = start_mono_ns_ + scheduled;
    core::sleep_until_ns(CLOCK_MONOTONIC, due);
    lateness_us_.push_back(1e-3 * static_cast<double>(now_ns(CLOCK_MONOTONIC) - due));
  }
  for (std::size_t k = 0; k < n; ++k) emit(frames[k]);
}

std::string TelemetryStreamer::lateness_summary() const {
  if (lateness_us_.empty()) return "";
  std::vector<double> v = lateness_us_;
  std::sort(v.begin(), v.end());
  auto pct = [&](double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]; };
  char buf[160];
  std::snprintf(buf, sizeof buf, "send time behind schedule [us]: p50 %.1f, p99 %.1f, max %.1f (%zu frames)", pct(0.5),
                pct(0.99), v.back(), v.size());
  return buf;
}

void TelemetryStreamer::finish() {
  std::array<can::CanFrame, can::TelemetryEncoder::kMaxFramesPerAdd> frames;
  const std::size_t n = encoder_.flush(frames);
  for (std::size_t k = 0; k < n; ++k) emit(frames[k]);
  if (candump_.is_open()) candump_.flush();
}

}  // namespace rpem::tools
