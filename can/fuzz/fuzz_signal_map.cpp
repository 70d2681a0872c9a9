// libFuzzer target for the signal-map decoder (can/include/rpem/can/signal_map.hpp). The first input byte
// picks a map — rotor-frame values in little-endian standard frames with an instantaneous trigger; phase
// values with theta_el in big-endian extended frames, averaged; or IEEE 754 floats (binary32 and binary64,
// both byte orders, averaged) — and the rest is a stream of frames
//   [a frame record, fuzz_frame.hpp][t step, 2 bytes]
// The rotor-frame map stamps samples with a 4-bit drive clock (wrapping every 16 counts, the wraps told by
// the receive times), the float map with a binary64 one (any value, NaN and ±∞ among them).
// The decoder must never crash, deliver only finite samples (optional quantities finite or NaN, "not
// reported", never ±∞) with t_start ≤ t and increasing t, and count every frame once. The dictionary
// (corpus_signal_map.dict) holds IEEE NaN, ±∞, −0, subnormals and the largest finite values in both orders.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>

#include "fuzz_frame.hpp"
#include "rpem/can/signal_map.hpp"

namespace {

using rpem::can::SampleField;
using rpem::can::SignalSpec;

rpem::can::SignalMap rotor_frame_map() {
  rpem::can::SignalMap m;
  m.trigger_id = 0x20;
  m.frames.push_back({0x10,
                      false,
                      8,
                      {{SampleField::kIdA, 0, 16, false, true, 0.01, 0.0},
                       {SampleField::kIqA, 16, 16, false, true, 0.01, 0.0},
                       {SampleField::kUdV, 32, 16, false, true, 0.1, 0.0},
                       {SampleField::kUqV, 48, 16, false, true, 0.1, 0.0}}});
  m.frames.push_back(
      {0x20,
       false,
       7,
       {{SampleField::kSpeedMechRpm, 0, 32, false, true, 1.0, 0.0},
        {SampleField::kUdcV, 32, 16, false, false, 0.1, -5.0},
        {SampleField::kTSampleS, 48, 4, false, false, 1e-5, 0.0}}});  // the drive's clock: wraps every 16 counts
  m.pole_pairs = 7;
  return m;
}

rpem::can::SignalMap phase_map() {
  rpem::can::SignalMap m;
  m.trigger_id = 0x18FF0002;
  m.trigger_extended = true;
  m.averaged = true;
  m.frames.push_back({0x18FF0001,
                      true,
                      8,
                      {{SampleField::kIaA, 7, 16, true, true, 0.001, 0.0},
                       {SampleField::kIbA, 23, 16, true, true, 0.001, 0.0},
                       {SampleField::kThetaElRad, 39, 16, true, false, 9.5873799e-5, 0.0},
                       {SampleField::kErpm, 55, 16, true, true, 1.0, 0.0}}});
  m.frames.push_back({0x18FF0002,
                      true,
                      8,
                      {{SampleField::kUaV, 7, 20, true, true, 0.001, 0.0},
                       {SampleField::kUbV, 19, 20, true, true, 0.001, 0.0},
                       {SampleField::kUcV, 48, 16, false, true, 0.01, 0.0}}});
  return m;
}

rpem::can::SignalMap float_map() {
  using rpem::can::ValueType;
  const auto f = [](SampleField field, int start, int length, bool big, ValueType t, double scale = 1.0,
                    double offset = 0.0) {
    SignalSpec s{field, start, length, big, false, scale, offset};
    s.value_type = t;
    return s;
  };
  constexpr ValueType k32 = ValueType::kFloat32, k64 = ValueType::kFloat64;
  rpem::can::SignalMap m;
  m.trigger_id = 0x32;
  m.averaged = true;
  m.frames.push_back({0x30, false, 8, {f(SampleField::kIdA, 0, 32, false, k32), f(SampleField::kIqA, 39, 32, true, k32)}});
  m.frames.push_back(
      {0x31, false, 8, {f(SampleField::kUdV, 0, 32, false, k32, 1e3), f(SampleField::kUqV, 32, 32, false, k32, 1e3)}});
  m.frames.push_back({0x32, false, 8, {f(SampleField::kOmegaElRadS, 7, 64, true, k64)}});
  m.frames.push_back({0x33, false, 8, {f(SampleField::kUdcV, 0, 64, false, k64, 1e12)}});
  m.frames.push_back({0x34, false, 4, {f(SampleField::kTWindingC, 7, 32, true, k32, 0.1, -40.0)}});
  m.frames.push_back({0x35, false, 8, {f(SampleField::kTSampleS, 0, 64, false, k64, 1e-3)}});  // the drive's ms
  return m;
}

/// An optional quantity is a number or NaN (not reported), never ±∞.
bool optional_ok(double v) noexcept { return !std::isinf(v); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const rpem::can::SignalMap maps[3] = {rotor_frame_map(), phase_map(), float_map()};
  const rpem::can::SignalMap& map = maps[data[0] % 3];
  if (!rpem::can::check_layout(map).empty() || !rpem::can::missing_quantities(map).empty()) std::abort();
  rpem::can::SignalMapDecoder decoder(map);
  std::size_t at = 1;
  std::int64_t t = 0, last_t = std::numeric_limits<std::int64_t>::min();  // a drive clock may read negative
  std::uint64_t samples = 0, offered = 0;
  rpem::can::CanFrame f;
  while (rpem::can::fuzz::read_frame(data, size, at, f)) {
    if (at + 2 <= size) {
      t += 1 + (data[at] | (data[at + 1] << 8));
      at += 2;
    }
    rpem::core::AveragedSample s;
    ++offered;
    if (decoder.decode(f, t, s)) {
      ++samples;
      if (!s.i_dq_A.allFinite() || !s.u_dq_V.allFinite() || !std::isfinite(s.omega_el_rad_s)) std::abort();
      if (!optional_ok(s.u_dc_V) || !optional_ok(s.t_winding_C) || !optional_ok(s.t_magnet_C) || !optional_ok(s.t_drive_C))
        std::abort();
      if (s.t_start_ns > s.t_ns || s.t_ns <= last_t) std::abort();
      last_t = s.t_ns;
    }
  }
  const auto& c = decoder.counters();
  if (c.samples != samples || c.frames != offered) std::abort();
  return 0;
}
