#pragma once
// Helpers for the CAN tests: samples and the frames they encode to.

#include <random>
#include <vector>

#include "rpem/can/decoder.hpp"
#include "rpem/can/encoder.hpp"
#include "rpem/can/signal_map.hpp"
#include "rpem/core/frames.hpp"

namespace rpem::test {

inline core::DriveSample random_sample(std::mt19937_64& rng, std::int64_t t_ns) {
  std::uniform_real_distribution<double> cur(-20.0, 20.0), volt(-300.0, 300.0), ang(-3.1, 3.1), w(-600.0, 600.0);
  core::DriveSample s;
  s.t_ns = t_ns;
  s.theta_el_rad = ang(rng);
  s.omega_el_rad_s = w(rng);
  s.u_dc_V = 220.0 + cur(rng);
  s.u_V = {volt(rng), volt(rng), volt(rng)};
  s.i_A = {cur(rng), cur(rng), cur(rng)};
  return s;
}

/// Encodes the samples (and flushes); returns the frames in send order.
inline std::vector<can::CanFrame> encode_all(can::TelemetryEncoder& enc, const std::vector<core::DriveSample>& samples) {
  std::vector<can::CanFrame> frames;
  std::array<can::CanFrame, can::TelemetryEncoder::kMaxFramesPerAdd> buf;
  for (const auto& s : samples) {
    const std::size_t n = enc.add(s, 0, buf);
    frames.insert(frames.end(), buf.begin(), buf.begin() + static_cast<long>(n));
  }
  const std::size_t n = enc.flush(buf);
  frames.insert(frames.end(), buf.begin(), buf.begin() + static_cast<long>(n));
  return frames;
}

inline std::vector<core::DriveSample> decode_all(can::TelemetryDecoder& dec, const std::vector<can::CanFrame>& frames) {
  std::vector<core::DriveSample> out;
  std::array<core::DriveSample, 3> buf;
  for (const auto& f : frames) {
    const std::size_t n = dec.decode(f, 0, buf);  // received at once: the drive's clock alone tells time
    out.insert(out.end(), buf.begin(), buf.begin() + static_cast<long>(n));
  }
  return out;
}

/// The samples a signal map's decoder completes from the frames, every frame received at rx_ns.
inline std::vector<core::AveragedSample> decode_all(can::SignalMapDecoder& dec, const std::vector<can::CanFrame>& frames,
                                                    std::int64_t rx_ns) {
  std::vector<core::AveragedSample> out;
  core::AveragedSample s;
  for (const auto& f : frames) {
    if (dec.decode(f, rx_ns, s)) out.push_back(s);
  }
  return out;
}

}  // namespace rpem::test
