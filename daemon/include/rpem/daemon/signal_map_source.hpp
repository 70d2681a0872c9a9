#pragma once
// `source: {type: signal_map, signal_map: {interface: can0, map: signal-maps/my-drive.yaml}}` — any drive
// that broadcasts its own frames (CiA 402 PDOs, a VESC LispBM script, custom firmware), read through a
// signal map (docs/sources.md, "Signal maps"; examples in config/signal-maps/). The map is loaded when the
// configuration is: a map that does not give the quantities the estimator needs is refused then, naming
// the map file and the quantity (rpemd exits 78).
//
// Which estimator: a map of instantaneous phase quantities with the angle (averaged: false; i_a, i_b,
// theta_el) gives phase samples at the drive's rate, stepped by DriveEstimator; every other map gives
// averaged rotor-frame samples (AveragedDriveEstimator). Samples are stamped with the kernel receive time
// of the map's trigger frame. Frames with ids the map does not name are ignored and counted.

#include <memory>
#include <string>

#include "rpem/can/signal_map.hpp"
#include "rpem/daemon/read_at_parse.hpp"
#include "rpem/daemon/source.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::daemon {

struct SignalMapSource {
  static constexpr const char* kType = "signal_map";
  struct Options {
    std::string interface = "can0";
    std::string map;                          ///< the map file (relative paths: to the configuration's directory)
    SampleKind kind = SampleKind::kAveraged;  ///< from the map, when it was loaded
    bool gives_u_dc = false;                  ///< the map carries the DC link (a dead time in seconds needs it)
    ReadAtParse<can::SignalMap> map_read;     ///< the map as checked: the source runs on it
    bool operator==(const Options&) const = default;
  };
  /// Loads the map (io::ConfigError naming the map file if it is bad or lacks a needed quantity); `make` runs on
  /// what this read.
  [[nodiscard]] static Options parse(io::YamlMap& section, const std::string& base_dir);
  [[nodiscard]] static SampleKind sample_kind(const Options& o) noexcept { return o.kind; }
  [[nodiscard]] static std::unique_ptr<SampleSource> make(const Options& options);
};

/// The kind of sample a map gives (see above).
[[nodiscard]] SampleKind sample_kind_of(const can::SignalMap& map) noexcept;

/// Turns a signal map decoder's samples into the source's kind: phase samples keep the angle of the
/// trigger (from the decoder), averaged ones pass as they are.
class SignalMapSampler {
 public:
  explicit SignalMapSampler(can::SignalMap map);
  /// One frame received at rx_ns (CLOCK_REALTIME): true when it completed a sample.
  [[nodiscard]] bool on_frame(const can::CanFrame& f, std::int64_t rx_ns, SourceSample& out) noexcept;
  [[nodiscard]] SampleKind kind() const noexcept { return kind_; }
  [[nodiscard]] const can::SignalMapCounters& counters() const noexcept { return decoder_.counters(); }
  /// The decoder's counters as diagnostics rows (can_*).
  void report(DiagnosticsRows& rows) const noexcept;

 private:
  can::SignalMapDecoder decoder_;
  SampleKind kind_;
};

}  // namespace rpem::daemon
