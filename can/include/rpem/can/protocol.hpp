#pragma once
// The rpem telemetry protocol, version 1 (can/rpem_telemetry.dbc; docs/can-protocol.md).
//
// CAN FD, ID 0x100, 64 bytes, up to three consecutive samples per frame:
//   0–1 CRC-16 · 2 alive counter · 3 version<<4 | n_samples · 4–7 t_first [µs, u32, wraps]
//   8–9 sample period [µs, u16] · 10–11 u_dc [0.02 V, u16] · 12 status
//   13 + 16·j, j < n_samples:  i_a i_b i_c [1 mA, i16] · u_a u_b u_c [20 mV, i16]
//                              ϑ_el [2π/65536 rad, u16] · ω_el [0.05 rad/s, i16]
//
// Classic CAN (1 Mbit/s, reduced sample rate), five 8-byte frames per sample, IDs 0x110–0x114, each
// with CRC-16 · counter (= sample counter) and five payload bytes:
//   0x110 i_a i_b status · 0x111 i_c ϑ_el · 0x112 u_a u_b · 0x113 u_c ω_el · 0x114 u_dc t[µs, low 24 bits]
//
// Temperatures (either bus), one classic 8-byte frame, ID 0x118, at the sensors' own slow rate:
//   0–1 CRC-16 · 2 alive counter (its own) · 3–4 T_winding · 5–6 T_coolant [0.1 °C, i16] · 7 zero
// The readings go with the next sample delivered after the frame.
//
// Little endian throughout. Reserved raw codes: i16 −32768 and u16 65535 mean "no valid value" (NaN);
// i16 ±32767 means "saturated" (out of range). Data IDs for the E2E CRC: 0x5100 + (CAN ID − 0x100).

#include <array>
#include <cmath>
#include <cstdint>

#include "rpem/can/frame.hpp"

namespace rpem::can::protocol {

inline constexpr std::uint8_t kVersion = 1;

inline constexpr std::uint32_t kFdId = 0x100;
inline constexpr std::uint8_t kFdLength = 64;
inline constexpr int kFdHeaderBytes = 13;
inline constexpr int kFdSampleBytes = 16;
inline constexpr int kFdMaxSamples = 3;

inline constexpr std::uint32_t kClassicFirstId = 0x110;
inline constexpr int kClassicFrames = 5;
inline constexpr std::uint8_t kClassicLength = 8;

inline constexpr std::uint32_t kTemperatureId = 0x118;
/// How often the encoder sends the temperatures a drive's samples carry: a thermal time constant is seconds
/// or more (docs/thermal.md), so 10 Hz resolves it and costs the bus 0.14 % at 1 Mbit/s.
inline constexpr std::int64_t kTemperaturePeriod_ns = 100'000'000;

/// Every telemetry CAN ID: what a receiver's kernel filter lets through.
inline constexpr std::array<std::uint32_t, 2 + kClassicFrames> kTelemetryIds = {
    kFdId,         kClassicFirstId, kClassicFirstId + 1, kClassicFirstId + 2, kClassicFirstId + 3, kClassicFirstId + 4,
    kTemperatureId};

[[nodiscard]] constexpr std::uint16_t data_id(std::uint32_t can_id) noexcept {
  return static_cast<std::uint16_t>(0x5100 + (can_id - kFdId));
}

// Resolutions (one LSB) of the scaled integers.
inline constexpr double kCurrentLsb_A = 0.001;
inline constexpr double kVoltageLsb_V = 0.02;
inline constexpr double kAngleLsb_rad = 2.0 * 3.14159265358979323846 / 65536.0;
inline constexpr double kSpeedLsb_rad_s = 0.05;
inline constexpr double kDcLinkLsb_V = 0.02;
inline constexpr double kTemperatureLsb_C = 0.1;

inline constexpr std::int16_t kInvalidI16 = INT16_MIN;
inline constexpr std::int16_t kSaturatedI16 = INT16_MAX;
inline constexpr std::uint16_t kInvalidU16 = UINT16_MAX;
inline constexpr std::uint16_t kSaturatedU16 = UINT16_MAX - 1;

/// Status bits of the drive.
namespace status {
inline constexpr std::uint8_t kPwmEnabled = 1U << 0;
inline constexpr std::uint8_t kFault = 1U << 1;
inline constexpr std::uint8_t kCurrentLimited = 1U << 2;
inline constexpr std::uint8_t kVoltageLimited = 1U << 3;
inline constexpr std::uint8_t kAngleInvalid = 1U << 6;  ///< a sample in this frame had no valid angle
inline constexpr std::uint8_t kSimulated = 1U << 7;
}  // namespace status

// Scaled-integer conversions, one place for encoder and decoder.
[[nodiscard]] inline std::int16_t to_i16(double value, double lsb) noexcept {
  if (!std::isfinite(value)) return kInvalidI16;
  const double raw = std::round(value / lsb);
  if (raw >= kSaturatedI16) return kSaturatedI16;
  if (raw <= -kSaturatedI16) return -kSaturatedI16;
  return static_cast<std::int16_t>(raw);
}
[[nodiscard]] inline std::uint16_t to_u16(double value, double lsb) noexcept {
  if (!std::isfinite(value)) return kInvalidU16;
  const double raw = std::round(value / lsb);
  if (raw >= kSaturatedU16) return kSaturatedU16;
  if (raw <= 0.0) return 0;
  return static_cast<std::uint16_t>(raw);
}
/// The angle wraps: any finite angle maps onto [0, 2π). Every code is a valid angle, so a missing
/// angle is flagged with status::kAngleInvalid instead (the encoder does that).
[[nodiscard]] inline std::uint16_t angle_to_u16(double theta_rad) noexcept {
  if (!std::isfinite(theta_rad)) return 0;
  const double turns = theta_rad / (2.0 * 3.14159265358979323846);
  const double frac = turns - std::floor(turns);
  return static_cast<std::uint16_t>(static_cast<std::uint32_t>(std::lround(frac * 65536.0)) & 0xFFFF);
}
/// Inverse of angle_to_u16, in (−π, π].
[[nodiscard]] inline double angle_of(std::uint16_t raw) noexcept {
  const double a = raw * kAngleLsb_rad;
  return a > 3.14159265358979323846 ? a - 2.0 * 3.14159265358979323846 : a;
}

// Little-endian field access.
inline void put_u16(CanFrame& f, int at, std::uint16_t v) noexcept {
  f.data[static_cast<std::size_t>(at)] = static_cast<std::uint8_t>(v & 0xFF);
  f.data[static_cast<std::size_t>(at) + 1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_i16(CanFrame& f, int at, std::int16_t v) noexcept { put_u16(f, at, static_cast<std::uint16_t>(v)); }
inline void put_u32(CanFrame& f, int at, std::uint32_t v) noexcept {
  put_u16(f, at, static_cast<std::uint16_t>(v & 0xFFFF));
  put_u16(f, at + 2, static_cast<std::uint16_t>(v >> 16));
}
[[nodiscard]] inline std::uint16_t get_u16(const CanFrame& f, int at) noexcept {
  return static_cast<std::uint16_t>(f.data[static_cast<std::size_t>(at)] | (f.data[static_cast<std::size_t>(at) + 1] << 8));
}
[[nodiscard]] inline std::int16_t get_i16(const CanFrame& f, int at) noexcept {
  return static_cast<std::int16_t>(get_u16(f, at));
}
[[nodiscard]] inline std::uint32_t get_u32(const CanFrame& f, int at) noexcept {
  return static_cast<std::uint32_t>(get_u16(f, at)) | (static_cast<std::uint32_t>(get_u16(f, at + 2)) << 16);
}

}  // namespace rpem::can::protocol
