#include "rpem/can/encoder.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/can/e2e.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/core/assert.hpp"
#include "rpem/core/frames.hpp"

namespace rpem::can {

namespace p = protocol;

TelemetryEncoder::TelemetryEncoder(BusMode mode, int samples_per_frame) noexcept
    : mode_(mode), samples_per_frame_(std::clamp(samples_per_frame, 1, p::kFdMaxSamples)) {}

TelemetryEncoder::Quantized TelemetryEncoder::quantize(const core::DriveSample& s) noexcept {
  const core::Rotation rot = core::Rotation::of(s.theta_el_rad);
  auto phases = [&](core::Frame f, const core::Vec3& v) -> core::Vec3 {
    if (f == core::Frame::kAbc) return v;
    const core::Vec2 ab = f == core::Frame::kAlphaBeta ? core::Vec2(v.head<2>()) : core::inverse_park(v.head<2>(), rot);
    return core::inverse_clarke(ab);
  };
  const core::Vec3 i = phases(s.current_frame, s.i_A);
  const core::Vec3 u = phases(s.voltage_frame, s.u_V);
  Quantized q{};
  q.t_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(s.t_ns / 1000) & 0xFFFFFFFFULL);
  for (int k = 0; k < 3; ++k) {
    q.i[static_cast<std::size_t>(k)] = p::to_i16(i[k], p::kCurrentLsb_A);
    q.u[static_cast<std::size_t>(k)] = p::to_i16(u[k], p::kVoltageLsb_V);
  }
  q.theta = p::angle_to_u16(s.theta_el_rad);
  q.omega = p::to_i16(s.omega_el_rad_s, p::kSpeedLsb_rad_s);
  q.u_dc = p::to_u16(s.u_dc_V, p::kDcLinkLsb_V);
  return q;
}

std::size_t TelemetryEncoder::add(const core::DriveSample& sample, std::uint8_t status, std::span<CanFrame> out) noexcept {
  RPEM_ASSERT(out.size() >= kMaxFramesPerAdd, "room for every frame one sample can complete");
  const Quantized q = quantize(sample);
  if (!std::isfinite(sample.theta_el_rad)) status |= p::status::kAngleInvalid;
  if (mode_ == BusMode::kClassic) {
    const std::size_t n = emit_classic(q, status, out);
    return n + emit_temperatures(sample, out.subspan(n));
  }

  std::size_t n = 0;
  // A frame holds equally spaced samples only; a sample off the grid closes the frame.
  if (n_pending_ == 1) {
    period_ns_ = sample.t_ns - first_t_ns_;
  } else if (n_pending_ > 1 && sample.t_ns - first_t_ns_ != n_pending_ * period_ns_) {
    n = emit_fd(out);
  }
  if (n_pending_ == 0) {
    first_t_ns_ = sample.t_ns;
    status_ = 0;
  }
  status_ |= status;
  pending_[static_cast<std::size_t>(n_pending_++)] = q;
  if (n_pending_ == samples_per_frame_) n += emit_fd(out.subspan(n));
  return n + emit_temperatures(sample, out.subspan(n));
}

std::size_t TelemetryEncoder::emit_temperatures(const core::DriveSample& s, std::span<CanFrame> out) noexcept {
  if (std::isnan(s.t_winding_C) && std::isnan(s.t_coolant_C)) return 0;
  if (sent_temperatures_ && s.t_ns - temperatures_t_ns_ < p::kTemperaturePeriod_ns) return 0;
  sent_temperatures_ = true;
  temperatures_t_ns_ = s.t_ns;
  CanFrame& f = out[0];
  f = CanFrame{};
  f.id = p::kTemperatureId;
  f.len = p::kClassicLength;
  p::put_i16(f, 3, p::to_i16(s.t_winding_C, p::kTemperatureLsb_C));
  p::put_i16(f, 5, p::to_i16(s.t_coolant_C, p::kTemperatureLsb_C));
  e2e_protect(f, p::data_id(f.id), temperature_counter_++);
  return 1;
}

std::size_t TelemetryEncoder::flush(std::span<CanFrame> out) noexcept {
  return mode_ == BusMode::kFd && n_pending_ > 0 ? emit_fd(out) : 0;
}

std::size_t TelemetryEncoder::emit_fd(std::span<CanFrame> out) noexcept {
  CanFrame& f = out[0];
  f = CanFrame{};
  f.id = p::kFdId;
  f.fd = true;
  f.len = p::kFdLength;
  const Quantized& first = pending_[0];
  f.data[3] = static_cast<std::uint8_t>((p::kVersion << 4) | n_pending_);
  p::put_u32(f, 4, first.t_us);
  const std::int64_t period_us = n_pending_ > 1 ? period_ns_ / 1000 : 0;
  p::put_u16(f, 8, static_cast<std::uint16_t>(std::clamp<std::int64_t>(period_us, 0, 65535)));
  p::put_u16(f, 10, first.u_dc);
  f.data[12] = status_;
  for (int j = 0; j < n_pending_; ++j) {
    const Quantized& q = pending_[static_cast<std::size_t>(j)];
    const int at = p::kFdHeaderBytes + j * p::kFdSampleBytes;
    for (int k = 0; k < 3; ++k) {
      p::put_i16(f, at + 2 * k, q.i[static_cast<std::size_t>(k)]);
      p::put_i16(f, at + 6 + 2 * k, q.u[static_cast<std::size_t>(k)]);
    }
    p::put_u16(f, at + 12, q.theta);
    p::put_i16(f, at + 14, q.omega);
  }
  e2e_protect(f, p::data_id(p::kFdId), counter_++);
  n_pending_ = 0;
  return 1;
}

std::size_t TelemetryEncoder::emit_classic(const Quantized& q, std::uint8_t status, std::span<CanFrame> out) noexcept {
  for (int k = 0; k < p::kClassicFrames; ++k) {
    CanFrame& f = out[static_cast<std::size_t>(k)];
    f = CanFrame{};
    f.id = p::kClassicFirstId + static_cast<std::uint32_t>(k);
    f.len = p::kClassicLength;
    switch (k) {
      case 0:
        p::put_i16(f, 3, q.i[0]);
        p::put_i16(f, 5, q.i[1]);
        f.data[7] = status;
        break;
      case 1:
        p::put_i16(f, 3, q.i[2]);
        p::put_u16(f, 5, q.theta);
        break;
      case 2:
        p::put_i16(f, 3, q.u[0]);
        p::put_i16(f, 5, q.u[1]);
        break;
      case 3:
        p::put_i16(f, 3, q.u[2]);
        p::put_i16(f, 5, q.omega);
        break;
      default:
        p::put_u16(f, 3, q.u_dc);
        f.data[5] = static_cast<std::uint8_t>(q.t_us & 0xFF);
        f.data[6] = static_cast<std::uint8_t>((q.t_us >> 8) & 0xFF);
        f.data[7] = static_cast<std::uint8_t>((q.t_us >> 16) & 0xFF);
        break;
    }
    e2e_protect(f, p::data_id(f.id), counter_);
  }
  ++counter_;
  return p::kClassicFrames;
}

}  // namespace rpem::can
