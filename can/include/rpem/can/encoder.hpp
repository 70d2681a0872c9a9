#pragma once
// Drive samples → telemetry frames (the drive's side; used by `rpem sim --can` and `rpem replay`).
// Pure: no I/O. Samples are quantised to the protocol's resolution here and nowhere else.

#include <array>
#include <cstdint>
#include <span>

#include "rpem/can/frame.hpp"
#include "rpem/core/drive_sample.hpp"

namespace rpem::can {

enum class BusMode { kFd, kClassic };

class TelemetryEncoder {
 public:
  /// The most frames one add() completes: a sample's five classic frames and a temperature frame.
  static constexpr std::size_t kMaxFramesPerAdd = 6;

  /// samples_per_frame: 1–3 (FD only; classic always sends five frames per sample).
  explicit TelemetryEncoder(BusMode mode, int samples_per_frame = 3) noexcept;

  /// Adds one sample (any frame: abc, αβ or dq are converted to phases). Returns the frames that
  /// became complete (0–kMaxFramesPerAdd) in `out`, which must hold kMaxFramesPerAdd. A sample that carries a
  /// temperature (t_winding_C, t_coolant_C) adds a temperature frame after its own when
  /// protocol::kTemperaturePeriod_ns of drive time has passed since the last one.
  [[nodiscard]] std::size_t add(const core::DriveSample& sample, std::uint8_t status, std::span<CanFrame> out) noexcept;
  /// Emits a partially filled FD frame, if any.
  [[nodiscard]] std::size_t flush(std::span<CanFrame> out) noexcept;

  [[nodiscard]] BusMode mode() const noexcept { return mode_; }

 private:
  struct Quantized {
    std::uint32_t t_us;
    std::array<std::int16_t, 3> i;
    std::array<std::int16_t, 3> u;
    std::uint16_t theta;
    std::int16_t omega;
    std::uint16_t u_dc;
  };
  [[nodiscard]] static Quantized quantize(const core::DriveSample& s) noexcept;
  [[nodiscard]] std::size_t emit_fd(std::span<CanFrame> out) noexcept;
  [[nodiscard]] std::size_t emit_classic(const Quantized& q, std::uint8_t status, std::span<CanFrame> out) noexcept;
  /// The temperature frame a sample is due (0 or 1 frames).
  [[nodiscard]] std::size_t emit_temperatures(const core::DriveSample& s, std::span<CanFrame> out) noexcept;

  BusMode mode_;
  int samples_per_frame_;
  std::array<Quantized, 3> pending_{};
  int n_pending_ = 0;
  std::int64_t first_t_ns_ = 0;
  std::int64_t period_ns_ = 0;
  std::uint8_t status_ = 0;
  std::uint8_t counter_ = 0;
  bool sent_temperatures_ = false;
  std::int64_t temperatures_t_ns_ = 0;  ///< the drive time of the last temperature frame
  std::uint8_t temperature_counter_ = 0;
};

}  // namespace rpem::can
