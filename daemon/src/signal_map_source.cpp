#include "rpem/daemon/signal_map_source.hpp"

#include <array>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "rpem/can/socketcan.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/socketcan_source.hpp"
#include "rpem/io/signal_map_config.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;
using can::SignalMapCounters;

constexpr std::array<CounterRow<SignalMapCounters, std::uint64_t>, 7> kMapRows{{
    {&SignalMapCounters::frames, &Diag::can_frames},
    {&SignalMapCounters::unknown_id, &Diag::can_unknown_id},
    {&SignalMapCounters::wrong_length, &Diag::can_wrong_dlc},
    {&SignalMapCounters::incomplete, &Diag::can_incomplete},
    {&SignalMapCounters::non_finite, &Diag::can_invalid_value},
    {&SignalMapCounters::stale, &Diag::can_stale},
    {&SignalMapCounters::no_reading, &Diag::temperature_no_reading},
}};
static_assert(kMapRows.size() + kChannelRows.size() + 1 <= DiagnosticsRows::kMaxCounts);

bool maps(const can::SignalMap& map, can::SampleField field) noexcept {
  for (const can::FrameSpec& f : map.frames) {
    for (const can::SignalSpec& s : f.signals) {
      if (s.field == field) return true;
    }
  }
  return false;
}

class SignalMapSampleSource final : public SampleSource {
 public:
  SignalMapSampleSource(SignalMapSource::Options o, can::SignalMap map) : options_(std::move(o)), sampler_(std::move(map)) {}

  void run(const std::atomic<bool>& stop, SourceOutput& out) override {
    can::SocketCanChannel::Options o;
    o.interface = options_.interface;  // every frame: those the map does not name are counted
    can::SocketCanChannel channel(o);
    ChannelNotices notices;
    std::array<can::ReceivedFrame, 64> frames;
    SourceSample sample;
    while (!stop.load(std::memory_order_relaxed)) {
      const std::size_t n = channel.receive(frames, 50);
      const std::int64_t now = core::now_ns(CLOCK_REALTIME);
      for (std::size_t f = 0; f < n; ++f) {
        if (sampler_.on_frame(frames[f].frame, receive_time_ns(frames[f], now), sample)) out.push(sample);
      }
      report_when_due(out, channel, notices, options_.interface, [&](DiagnosticsRows& rows) { sampler_.report(rows); });
    }
  }
  [[nodiscard]] std::string name() const override { return options_.interface + " map " + options_.map; }

 private:
  SignalMapSource::Options options_;
  SignalMapSampler sampler_;
};

}  // namespace

SampleKind sample_kind_of(const can::SignalMap& map) noexcept {
  using F = can::SampleField;
  const bool phases = maps(map, F::kIaA) && maps(map, F::kIbA) && maps(map, F::kThetaElRad);
  return !map.averaged && phases ? SampleKind::kPhase : SampleKind::kAveraged;
}

SignalMapSampler::SignalMapSampler(can::SignalMap map) : decoder_(std::move(map)), kind_(sample_kind_of(decoder_.map())) {}

bool SignalMapSampler::on_frame(const can::CanFrame& f, std::int64_t rx_ns, SourceSample& out) noexcept {
  core::AveragedSample a;
  if (!decoder_.decode(f, rx_ns, a)) return false;
  if (kind_ == SampleKind::kAveraged) {
    out = a;
    return true;
  }
  // The rotor-frame values at the trigger's angle, which the estimator turns back with the same angle.
  core::DriveSample s;
  s.t_ns = a.t_ns;
  s.rx_ns = rx_ns;
  s.theta_el_rad = decoder_.latest(can::SampleField::kThetaElRad);
  s.omega_el_rad_s = a.omega_el_rad_s;
  s.u_dc_V = std::isnan(a.u_dc_V) ? 0.0 : a.u_dc_V;
  s.voltage_frame = core::Frame::kDq;
  s.u_V = core::Vec3(a.u_dq_V[0], a.u_dq_V[1], 0.0);
  s.current_frame = core::Frame::kDq;
  s.i_A = core::Vec3(a.i_dq_A[0], a.i_dq_A[1], 0.0);
  s.gap_before = a.gap_before;
  s.t_winding_C = a.t_winding_C;
  s.t_coolant_C = a.t_coolant_C;
  out = s;
  return true;
}

void SignalMapSampler::report(DiagnosticsRows& rows) const noexcept { rows.set_all(kMapRows, decoder_.counters()); }

SignalMapSource::Options SignalMapSource::parse(io::YamlMap& section, const std::string& base_dir) {
  Options o;
  o.interface = parse_interface(section);
  o.map = section.text("map");
  if (std::filesystem::path(o.map).is_relative())
    o.map = (std::filesystem::path(base_dir) / o.map).lexically_normal().string();
  section.finish();
  // Refused here, at start (and on a reload), naming the map file and what it lacks.
  o.map_read = ReadAtParse<can::SignalMap>(io::load_signal_map(o.map));
  o.kind = sample_kind_of(*o.map_read);
  o.gives_u_dc = maps(*o.map_read, can::SampleField::kUdcV);
  return o;
}

std::unique_ptr<SampleSource> SignalMapSource::make(const Options& options) {
  if (!options.map_read.has_value()) throw std::logic_error("signal map source: options not parsed");
  return std::make_unique<SignalMapSampleSource>(options, *options.map_read);
}

}  // namespace rpem::daemon
