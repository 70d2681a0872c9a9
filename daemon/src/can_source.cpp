#include "rpem/daemon/can_source.hpp"

#include <array>
#include <vector>

#include "rpem/can/decoder.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/can/socketcan.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/socketcan_source.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;

// Where the decoder and the socket count each bad-input class, and where diagnostics publish it.
constexpr std::array<CounterRow<can::DecoderCounters, std::uint64_t>, 13> kCanDecoderRows{{
    {&can::DecoderCounters::frames, &Diag::can_frames},
    {&can::DecoderCounters::unknown_id, &Diag::can_unknown_id},
    {&can::DecoderCounters::wrong_dlc, &Diag::can_wrong_dlc},
    {&can::DecoderCounters::bad_version, &Diag::can_bad_version},
    {&can::DecoderCounters::crc_error, &Diag::can_crc_error},
    {&can::DecoderCounters::frames_lost, &Diag::can_frames_lost},
    {&can::DecoderCounters::duplicated, &Diag::can_duplicated},
    {&can::DecoderCounters::reordered, &Diag::can_reordered},
    {&can::DecoderCounters::stale, &Diag::can_stale},
    {&can::DecoderCounters::out_of_range, &Diag::can_out_of_range},
    {&can::DecoderCounters::invalid_value, &Diag::can_invalid_value},
    {&can::DecoderCounters::incomplete, &Diag::can_incomplete},
    {&can::DecoderCounters::gaps, &Diag::can_gaps},
}};
static_assert(kCanDecoderRows.size() + kChannelRows.size() + 1 <= DiagnosticsRows::kMaxCounts);

class CanSampleSource final : public SampleSource {
 public:
  explicit CanSampleSource(CanSource::Options o) : options_(std::move(o)) {}

  void run(const std::atomic<bool>& stop, SourceOutput& out) override {
    can::SocketCanChannel::Options o;
    o.interface = options_.interface;
    o.ids.assign(can::protocol::kTelemetryIds.begin(), can::protocol::kTelemetryIds.end());
    can::SocketCanChannel channel(o);
    ChannelNotices notices;
    can::TelemetryDecoder decoder;
    std::vector<can::ReceivedFrame> frames(64);
    std::array<core::DriveSample, 3> samples;
    bool was_open = channel.is_open();
    while (!stop.load(std::memory_order_relaxed)) {
      const std::size_t n = channel.receive(frames, 50);
      const std::int64_t now = core::now_ns(CLOCK_REALTIME);
      if (channel.is_open() != was_open) {
        was_open = channel.is_open();
        if (!was_open) decoder.resynchronize();  // whatever arrives after the outage starts a new stream
      }
      for (std::size_t f = 0; f < n; ++f) {
        const std::size_t got = decoder.decode(frames[f].frame, receive_time_ns(frames[f], now), samples);
        for (std::size_t k = 0; k < got; ++k) {
          samples[k].rx_ns = frames[f].kernel_rx_ns;
          out.push(samples[k]);
        }
      }
      report_when_due(out, channel, notices, options_.interface,
                      [&](DiagnosticsRows& rows) { rows.set_all(kCanDecoderRows, decoder.counters()); });
    }
  }
  [[nodiscard]] std::string name() const override { return options_.interface; }

 private:
  CanSource::Options options_;
};

}  // namespace

CanSource::Options CanSource::parse(io::YamlMap& section, const std::string&) {
  Options o;
  o.interface = parse_interface(section);
  section.finish();
  return o;
}

std::unique_ptr<SampleSource> CanSource::make(const Options& options) { return std::make_unique<CanSampleSource>(options); }

}  // namespace rpem::daemon
