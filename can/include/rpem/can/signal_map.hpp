#pragma once
// A signal map: how a drive's own CAN frames (CiA 402 PDOs, a VESC LispBM script's frames, custom
// firmware, rpem's native frames) carry the quantities of an averaged rotor-frame sample, with DBC
// semantics per signal (start bit, length, byte order, sign, physical = raw·scale + offset), and the
// decoder that turns frames into samples (docs/sources.md). The map is built once (io/signal_map_config
// reads it from YAML); decoding is pure: no I/O, no allocation, no exceptions.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rpem/can/frame.hpp"
#include "rpem/can/sample_clock.hpp"
#include "rpem/core/averaged_sample.hpp"

namespace rpem::can {

/// The sample quantities a signal can carry, each in one unit (the map's `unit` must name it).
enum class SampleField : std::uint8_t {
  kIdA,
  kIqA,
  kUdV,
  kUqV,  // rotor frame
  kIaA,
  kIbA,
  kIcA,
  kUaV,
  kUbV,
  kUcV,  // phases (turned into the rotor frame at theta_el)
  kThetaElRad,
  kOmegaElRadS,
  kErpm,
  kSpeedMechRpm,  // speed: one of these
  kUdcV,
  kTWindingC,
  kTMagnetC,
  kTDriveC,
  kTCoolantC,  // the coolant's: the thermal network's boundary (docs/thermal.md)
  kTSampleS,   // the drive's own time of the sample (SampleClock)
  kCount
};
inline constexpr std::size_t kSampleFieldCount = static_cast<std::size_t>(SampleField::kCount);

/// The map's name of a field (`i_d`, …) and its unit (`A`, …); parse returns false for an unknown name.
[[nodiscard]] std::string_view field_name(SampleField f) noexcept;
[[nodiscard]] std::string_view field_unit(SampleField f) noexcept;
[[nodiscard]] bool parse_field(std::string_view name, SampleField& out) noexcept;

/// How a signal's raw bits are read, as DBC's `SIG_VALTYPE_` gives it: an integer (no SIG_VALTYPE_, or 0),
/// an IEEE 754 binary32 (1: 32 bits) or binary64 (2: 64 bits). Scale and offset apply to all three.
enum class ValueType : std::uint8_t { kInteger, kFloat32, kFloat64 };

struct SignalSpec {
  SampleField field = SampleField::kIdA;
  int start_bit = 0;        ///< DBC start bit: the LSB (little endian) or the MSB in DBC numbering (big endian)
  int length = 1;           ///< 1–64 bits
  bool big_endian = false;  ///< DBC @0 (Motorola); false: @1 (Intel)
  bool is_signed = false;   ///< two's complement (integers only: an IEEE float carries its own sign)
  double scale = 1.0, offset = 0.0;
  ValueType value_type = ValueType::kInteger;
  /// The raw value (integers, before scale and offset; sign-extended where signed) the drive sends where its sensor
  /// gives no reading (a temperature's: J1939's all-ones "not available", a firmware's −273.15 °C as a count): the
  /// field is then not received in that frame (SignalMapCounters::no_reading).
  std::optional<std::int64_t> no_reading_raw{};
};

struct FrameSpec {
  std::uint32_t id = 0;
  bool extended = false;
  std::uint8_t length = 8;  ///< the DLC the frame must have at least
  std::vector<SignalSpec> signals;
};

struct SignalMap {
  std::string name;
  std::vector<FrameSpec> frames;
  std::uint32_t trigger_id = 0;  ///< the frame that completes a sample (after its own signals are read)
  bool trigger_extended = false;
  /// true: the drive's values are means since its previous sample (window = previous trigger → this one);
  /// false: instantaneous values (t_start = t).
  bool averaged = false;
  int pole_pairs = 0;  ///< for speed_mech_rpm; 0: not given
};

/// Bits in [start, start+length) fit the frame's length and every signal is well formed (a float is 32 bits
/// for binary32 and 64 for binary64, starts on a byte boundary and is not `signed`): "" or the first
/// problem, naming the frame and signal.
[[nodiscard]] std::string check_layout(const SignalMap& map);
/// The map has a signal for the field.
[[nodiscard]] bool maps_field(const SignalMap& map, SampleField f) noexcept;
/// What the estimator needs and the map does not give: "" or a sentence naming the missing quantities
/// (current and voltage in the rotor frame or as phases with theta_el; a speed; pole pairs for a
/// mechanical speed).
[[nodiscard]] std::string missing_quantities(const SignalMap& map);

/// The raw bits of a signal, DBC semantics (sign-extended where signed). The frame must hold them.
[[nodiscard]] std::int64_t extract_raw(const CanFrame& f, const SignalSpec& s) noexcept;
/// The physical value: the raw bits as an integer or an IEEE float (value_type), times scale plus offset.
/// NaN or ±infinity when the frame carries them (or the scaled value overflows); the decoder drops those.
[[nodiscard]] double physical_value(const CanFrame& f, const SignalSpec& s) noexcept;

struct SignalMapCounters {
  std::uint64_t frames = 0;
  std::uint64_t samples = 0;
  std::uint64_t unknown_id = 0;    ///< ignored: not in the map
  std::uint64_t wrong_length = 0;  ///< shorter than the map's DLC, or FD where classic is mapped
  std::uint64_t incomplete = 0;    ///< a trigger before every needed quantity arrived since the last sample
  std::uint64_t non_finite = 0;    ///< a frame with a NaN or infinite value (dropped), or a sample that came out so
  std::uint64_t stale = 0;         ///< a sample the drive stamped (t_sample) at or before the previous one (dropped)
  std::uint64_t no_reading = 0;    ///< a temperature signal holding its no-reading value (SignalSpec::no_reading_raw)
  std::uint64_t error_frames = 0;
};

class SignalMapDecoder {
 public:
  /// The map must pass check_layout and missing_quantities (the caller refuses it otherwise).
  explicit SignalMapDecoder(SignalMap map);

  /// Reads one frame received at t_ns; true when it completed a sample (written to `out`), stamped t_ns, or
  /// with the drive's own time when the map carries t_sample.
  [[nodiscard]] bool decode(const CanFrame& f, std::int64_t t_ns, core::AveragedSample& out) noexcept;
  [[nodiscard]] const SignalMapCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const SignalMap& map() const noexcept { return map_; }
  /// The newest value of a field (0 before its first frame): e.g. the angle of the sample just completed,
  /// which a phase sample keeps (rpemd's signal_map source).
  [[nodiscard]] double latest(SampleField f) const noexcept { return values_[static_cast<std::size_t>(f)]; }

 private:
  [[nodiscard]] bool complete(std::int64_t t_ns, core::AveragedSample& out) noexcept;

  SignalMap map_;
  std::array<double, kSampleFieldCount> values_{};
  std::array<bool, kSampleFieldCount> fresh_{};   ///< received since the last sample
  std::array<bool, kSampleFieldCount> mapped_{};  ///< some signal carries it
  bool has_previous_ = false;
  std::int64_t previous_t_ns_ = 0;
  std::optional<SampleClock> clock_;  ///< when the map carries t_sample: the samples' times are the drive's
  SignalMapCounters counters_;
};

}  // namespace rpem::can
