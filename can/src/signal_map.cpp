#include "rpem/can/signal_map.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include "rpem/core/frames.hpp"
#include "rpem/core/units.hpp"

namespace rpem::can {
namespace {

struct FieldInfo {
  std::string_view name, unit;
};
constexpr std::array<FieldInfo, kSampleFieldCount> kFields = {{
    {"i_d", "A"},          {"i_q", "A"},          {"u_d", "V"},        {"u_q", "V"},          {"i_a", "A"},
    {"i_b", "A"},          {"i_c", "A"},          {"u_a", "V"},        {"u_b", "V"},          {"u_c", "V"},
    {"theta_el", "rad"},   {"omega_el", "rad/s"}, {"erpm", "rpm"},     {"speed_mech", "rpm"}, {"u_dc", "V"},
    {"T_winding", "degC"}, {"T_magnet", "degC"},  {"T_drive", "degC"}, {"T_coolant", "degC"}, {"t_sample", "s"},
}};

/// DBC bit positions of a signal, MSB first for big endian (the "sawtooth" numbering: bit 7 of byte 0 is
/// 7, the bit after bit 0 of a byte is bit 7 of the next), LSB first for little endian.
template <typename Visit>
bool walk_bits(const SignalSpec& s, int frame_bits, Visit&& visit) noexcept {
  int pos = s.start_bit;
  for (int k = 0; k < s.length; ++k) {
    if (pos < 0 || pos >= frame_bits) return false;
    visit(pos);
    if (s.big_endian) {
      pos = (pos % 8 == 0) ? pos + 15 : pos - 1;
    } else {
      ++pos;
    }
  }
  return true;
}

/// What is wrong with a float signal's layout, or "" (integers: nothing). IEEE 754 values are whole bytes
/// in every format that carries them (CiA 301 REAL32/REAL64 in PDOs, DBC SIG_VALTYPE_ 1/2): a float that
/// starts inside a byte is a map error, not a layout to decode.
std::string float_problem(const SignalSpec& s) {
  if (s.value_type == ValueType::kInteger) return {};
  const bool single = s.value_type == ValueType::kFloat32;
  const int bits = single ? 32 : 64;
  const char* name = single ? "an IEEE 754 binary32 (float)" : "an IEEE 754 binary64 (double)";
  if (s.length != bits) return std::string(name) + " is " + std::to_string(bits) + " bits, not " + std::to_string(s.length);
  // Byte-aligned: the LSB at bit 0 of a byte (little endian) or the MSB at bit 7 of a byte (big endian).
  if (s.start_bit % 8 != (s.big_endian ? 7 : 0)) {
    return std::string(name) + " must start on a byte boundary (start_bit " +
           (s.big_endian ? "8k+7 for big_endian" : "8k for little_endian") + ", not " + std::to_string(s.start_bit) + ")";
  }
  if (s.is_signed) return std::string(name) + " carries its own sign: leave out `signed`";
  return {};
}

/// What is wrong with a signal's no-reading value, or "": a temperature's only, an integer's, and one its bits hold.
std::string no_reading_problem(const SignalSpec& s) {
  if (!s.no_reading_raw) return {};
  if (s.field != SampleField::kTWindingC && s.field != SampleField::kTMagnetC && s.field != SampleField::kTDriveC &&
      s.field != SampleField::kTCoolantC)
    return "no_reading is a temperature sensor's (T_winding, T_magnet, T_drive, T_coolant)";
  if (s.value_type != ValueType::kInteger) return "no_reading is an integer signal's raw value (a float's is NaN)";
  const int bits = std::clamp(s.length, 1, 64);
  const std::int64_t raw = *s.no_reading_raw;
  const bool fits = s.is_signed
                        ? bits == 64 || (raw >= -(std::int64_t{1} << (bits - 1)) && raw < (std::int64_t{1} << (bits - 1)))
                        : raw >= 0 && (bits >= 63 || raw < (std::int64_t{1} << bits));
  if (!fits) {
    return "no_reading " + std::to_string(raw) + " is not a raw value of " + std::to_string(bits) +
           (s.is_signed ? " signed" : " unsigned") + " bits";
  }
  return {};
}

}  // namespace

std::string_view field_name(SampleField f) noexcept { return kFields[static_cast<std::size_t>(f)].name; }
std::string_view field_unit(SampleField f) noexcept { return kFields[static_cast<std::size_t>(f)].unit; }

bool parse_field(std::string_view name, SampleField& out) noexcept {
  for (std::size_t k = 0; k < kFields.size(); ++k) {
    if (kFields[k].name == name) {
      out = static_cast<SampleField>(k);
      return true;
    }
  }
  return false;
}

std::string check_layout(const SignalMap& map) {
  int clocks = 0;
  for (std::size_t i = 0; i < map.frames.size(); ++i) {
    const FrameSpec& f = map.frames[i];
    if (f.length > 64) return "frame " + std::to_string(f.id) + ": length above 64 bytes";
    for (std::size_t j = 0; j < i; ++j) {
      if (map.frames[j].id == f.id && map.frames[j].extended == f.extended) {
        return "frame " + std::to_string(f.id) + " is mapped twice";
      }
    }
    for (const SignalSpec& s : f.signals) {
      const std::string where = "frame " + std::to_string(f.id) + ", signal " + std::string(field_name(s.field));
      if (s.length < 1 || s.length > 64) return where + ": length must be 1-64 bits";
      if (!walk_bits(s, 8 * f.length, [](int) {}))
        return where + ": bits lie outside the frame's " + std::to_string(f.length) + " bytes";
      if (!std::isfinite(s.scale) || s.scale == 0.0 || !std::isfinite(s.offset))
        return where + ": scale must be finite and non-zero, offset finite";
      if (const std::string e = float_problem(s); !e.empty()) return std::string(where).append(": ").append(e);
      if (const std::string e = no_reading_problem(s); !e.empty()) return std::string(where).append(": ").append(e);
      if (s.field == SampleField::kTSampleS) {
        if (++clocks > 1) return where + ": t_sample is mapped twice (one clock stamps a sample)";
        if (s.scale < 0.0 || s.is_signed) return where + ": t_sample counts forward: unsigned, scale positive";
      }
    }
  }
  bool trigger = false;
  for (const FrameSpec& f : map.frames) trigger = trigger || (f.id == map.trigger_id && f.extended == map.trigger_extended);
  if (!trigger) return "the sample trigger " + std::to_string(map.trigger_id) + " is not one of the mapped frames";
  return {};
}

bool maps_field(const SignalMap& map, SampleField field) noexcept {
  return std::any_of(map.frames.begin(), map.frames.end(), [&](const FrameSpec& f) {
    return std::any_of(f.signals.begin(), f.signals.end(), [&](const SignalSpec& s) { return s.field == field; });
  });
}

std::string missing_quantities(const SignalMap& map) {
  auto has = [&](SampleField f) { return maps_field(map, f); };
  using F = SampleField;
  std::string missing;
  auto add = [&](const char* what) { missing += (missing.empty() ? "" : "; ") + std::string(what); };
  const bool phases_i = has(F::kIaA) && has(F::kIbA) && has(F::kThetaElRad);
  const bool phases_u = has(F::kUaV) && has(F::kUbV) && has(F::kUcV) && has(F::kThetaElRad);
  if (!(has(F::kIdA) && has(F::kIqA)) && !phases_i) add("current (i_d and i_q, or i_a, i_b and theta_el)");
  if (!(has(F::kUdV) && has(F::kUqV)) && !phases_u) add("voltage (u_d and u_q, or u_a, u_b, u_c and theta_el)");
  if (!has(F::kOmegaElRadS) && !has(F::kErpm) && !has(F::kSpeedMechRpm)) add("speed (omega_el, erpm or speed_mech)");
  if (has(F::kSpeedMechRpm) && !has(F::kOmegaElRadS) && !has(F::kErpm) && map.pole_pairs <= 0) {
    add("pole_pairs (to turn speed_mech into the electrical speed)");
  }
  return missing.empty() ? missing : "the map does not give what the estimator needs: " + missing;
}

std::int64_t extract_raw(const CanFrame& f, const SignalSpec& s) noexcept {
  std::uint64_t raw = 0;
  int k = 0;
  (void)walk_bits(s, 8 * f.len, [&](int pos) {
    const std::uint64_t bit = (f.data[static_cast<std::size_t>(pos / 8)] >> (pos % 8)) & 1U;
    if (s.big_endian) {
      raw = (raw << 1) | bit;  // MSB first
    } else {
      raw |= bit << k;  // LSB first
    }
    ++k;
  });
  if (s.is_signed && s.length < 64 && (raw >> (s.length - 1)) & 1U) raw |= ~std::uint64_t{0} << s.length;
  return static_cast<std::int64_t>(raw);
}

double physical_value(const CanFrame& f, const SignalSpec& s) noexcept {
  const std::int64_t raw = extract_raw(f, s);
  const auto bits = static_cast<std::uint64_t>(raw);
  double v = 0.0;
  switch (s.value_type) {
    case ValueType::kFloat32:
      v = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
      break;
    case ValueType::kFloat64:
      v = std::bit_cast<double>(bits);
      break;
    case ValueType::kInteger:
      v = s.is_signed ? static_cast<double>(raw) : static_cast<double>(bits);
      break;
  }
  return v * s.scale + s.offset;
}

SignalMapDecoder::SignalMapDecoder(SignalMap map) : map_(std::move(map)) {
  for (const FrameSpec& f : map_.frames) {
    for (const SignalSpec& s : f.signals) {
      mapped_[static_cast<std::size_t>(s.field)] = true;
      if (s.field == SampleField::kTSampleS)
        clock_.emplace(s.length, s.value_type != ValueType::kInteger, s.scale, s.offset);
    }
  }
}

bool SignalMapDecoder::decode(const CanFrame& f, std::int64_t t_ns, core::AveragedSample& out) noexcept {
  ++counters_.frames;
  if (f.error) {
    ++counters_.error_frames;
    return false;
  }
  const FrameSpec* spec = nullptr;
  for (const FrameSpec& s : map_.frames) {
    if (s.id == f.id && s.extended == f.extended) {
      spec = &s;
      break;
    }
  }
  if (!spec) {
    ++counters_.unknown_id;
    return false;
  }
  if (f.len < spec->length) {
    ++counters_.wrong_length;
    return false;
  }
  const bool trigger = f.id == map_.trigger_id && f.extended == map_.trigger_extended;
  auto no_reading = [&](const SignalSpec& s) { return s.no_reading_raw && extract_raw(f, s) == *s.no_reading_raw; };
  // A frame with a NaN or infinite value (an IEEE float signal) is dropped whole: none of its values is
  // delivered, and a dropped trigger ends the chain as an incomplete sample does.
  for (const SignalSpec& s : spec->signals) {
    if (!no_reading(s) && !std::isfinite(physical_value(f, s))) {
      ++counters_.non_finite;
      if (trigger) {
        fresh_.fill(false);
        has_previous_ = false;
      }
      return false;
    }
  }
  for (const SignalSpec& s : spec->signals) {
    if (no_reading(s)) {  // the sensor gave none: the field is not received (a temperature: absent from the sample)
      ++counters_.no_reading;
      continue;
    }
    values_[static_cast<std::size_t>(s.field)] = physical_value(f, s);
    fresh_[static_cast<std::size_t>(s.field)] = true;
    if (s.field == SampleField::kTSampleS)
      clock_->on_value(static_cast<std::uint64_t>(extract_raw(f, s)), values_[static_cast<std::size_t>(s.field)]);
  }
  if (!trigger) return false;
  return complete(t_ns, out);
}

bool SignalMapDecoder::complete(std::int64_t t_ns, core::AveragedSample& out) noexcept {
  using F = SampleField;
  // What arrived since the last sample; the next sample starts afresh either way.
  const std::array<bool, kSampleFieldCount> got = fresh_;
  fresh_.fill(false);
  auto has = [&](F f) { return got[static_cast<std::size_t>(f)]; };
  auto value = [&](F f) { return values_[static_cast<std::size_t>(f)]; };
  const bool dq_i = has(F::kIdA) && has(F::kIqA);
  const bool dq_u = has(F::kUdV) && has(F::kUqV);
  const bool abc_i =
      has(F::kIaA) && has(F::kIbA) && (has(F::kIcA) || !mapped_[static_cast<std::size_t>(F::kIcA)]) && has(F::kThetaElRad);
  const bool abc_u = has(F::kUaV) && has(F::kUbV) && has(F::kUcV) && has(F::kThetaElRad);
  const bool speed = has(F::kOmegaElRadS) || has(F::kErpm) || (has(F::kSpeedMechRpm) && map_.pole_pairs > 0);
  const bool time = !clock_ || has(F::kTSampleS);
  if (!((dq_i || abc_i) && (dq_u || abc_u) && speed && time)) {
    ++counters_.incomplete;
    has_previous_ = false;  // the next window does not start here
    return false;
  }
  if (clock_) {
    // The drive's time replaces the receive time; a clock that restarted starts a new chain.
    const std::int64_t rx_ns = t_ns;
    const SampleClock::Step step = clock_->close(rx_ns, t_ns);
    if (step == SampleClock::Step::kStale) {
      ++counters_.stale;
      has_previous_ = false;
      return false;
    }
    if (step == SampleClock::Step::kFirst) has_previous_ = false;
  }
  core::AveragedSample s;
  s.t_ns = t_ns;
  s.t_start_ns = map_.averaged && has_previous_ ? previous_t_ns_ : t_ns;
  s.gap_before = !has_previous_;
  const core::Rotation rot = core::Rotation::of(value(F::kThetaElRad));
  if (dq_i) {
    s.i_dq_A = {value(F::kIdA), value(F::kIqA)};
  } else {
    const double i_c = has(F::kIcA) ? value(F::kIcA) : -value(F::kIaA) - value(F::kIbA);  // Σi = 0
    s.i_dq_A = core::park(core::clarke(core::Vec3(value(F::kIaA), value(F::kIbA), i_c)), rot);
  }
  s.u_dq_V = dq_u ? core::Vec2(value(F::kUdV), value(F::kUqV))
                  : core::park(core::clarke(core::Vec3(value(F::kUaV), value(F::kUbV), value(F::kUcV))), rot);
  s.omega_el_rad_s = has(F::kOmegaElRadS) ? value(F::kOmegaElRadS)
                     : has(F::kErpm)      ? core::rpm_to_rad_s(value(F::kErpm))
                                          : core::rpm_to_rad_s(value(F::kSpeedMechRpm)) * map_.pole_pairs;
  auto optional = [&](F f) { return has(f) ? value(f) : std::numeric_limits<double>::quiet_NaN(); };
  s.u_dc_V = optional(F::kUdcV);
  s.t_winding_C = optional(F::kTWindingC);
  s.t_magnet_C = optional(F::kTMagnetC);
  s.t_drive_C = optional(F::kTDriveC);
  s.t_coolant_C = optional(F::kTCoolantC);
  if (!s.i_dq_A.allFinite() || !s.u_dq_V.allFinite() || !std::isfinite(s.omega_el_rad_s)) {
    ++counters_.non_finite;
    has_previous_ = false;
    return false;
  }
  has_previous_ = true;
  previous_t_ns_ = t_ns;
  out = s;
  ++counters_.samples;
  return true;
}

}  // namespace rpem::can
