#pragma once
// Telemetry frames → drive samples (the receiver's side; used by rpemd and `rpem record`). Pure: no
// I/O, no allocation, no exceptions. Every frame or sample that cannot be trusted is dropped and
// counted by kind; the next sample that passes carries gap_before so the estimator resynchronises.

#include <cstdint>
#include <limits>
#include <span>

#include "rpem/can/frame.hpp"
#include "rpem/can/sample_clock.hpp"
#include "rpem/core/drive_sample.hpp"

namespace rpem::can {

/// Counters by kind of bad input (published in diagnostics; numbers only ever grow).
struct DecoderCounters {
  std::uint64_t frames = 0;         ///< frames offered to the decoder
  std::uint64_t samples = 0;        ///< samples delivered
  std::uint64_t unknown_id = 0;     ///< not a telemetry ID
  std::uint64_t wrong_dlc = 0;      ///< wrong length or FD/classic type for the ID, or bad n_samples
  std::uint64_t bad_version = 0;    ///< protocol version other than 1
  std::uint64_t crc_error = 0;      ///< E2E CRC mismatch
  std::uint64_t frames_lost = 0;    ///< alive-counter jumps: frames (FD, temperatures) or samples (classic) missing
  std::uint64_t duplicated = 0;     ///< same counter as the previous frame
  std::uint64_t reordered = 0;      ///< counter behind the previous one
  std::uint64_t stale = 0;          ///< drive time not after the last delivered sample
  std::uint64_t out_of_range = 0;   ///< a saturated value (a saturated temperature: that reading dropped)
  std::uint64_t invalid_value = 0;  ///< a "no valid value" code, or an invalid angle
  std::uint64_t incomplete = 0;     ///< classic: a sample missing some of its five frames
  std::uint64_t gaps = 0;           ///< samples delivered with gap_before
};

class TelemetryDecoder {
 public:
  /// Decodes one frame, received at rx_ns (the host's clock: it tells how often the drive's time wrapped over
  /// a silence), into up to three samples (SI, phase frames, at the drive's time). Returns how many. A
  /// temperature frame's readings go with the next sample delivered (its t_winding_C, t_coolant_C; NaN on the
  /// others).
  [[nodiscard]] std::size_t decode(const CanFrame& frame, std::int64_t rx_ns, std::span<core::DriveSample> out) noexcept;

  /// Forgets the stream state (counters are kept): the next frame starts a new stream with a gap.
  void resynchronize() noexcept;

  [[nodiscard]] const DecoderCounters& counters() const noexcept { return counters_; }

 private:
  enum class Sequence { kNext, kFirst, kLost, kDuplicate, kReordered };
  [[nodiscard]] Sequence check_sequence(std::uint8_t counter, bool& has_last, std::uint8_t& last) noexcept;
  [[nodiscard]] std::size_t decode_fd(const CanFrame& f, std::int64_t rx_ns, std::span<core::DriveSample> out) noexcept;
  [[nodiscard]] std::size_t decode_classic(const CanFrame& f, std::int64_t rx_ns, std::span<core::DriveSample> out) noexcept;
  void decode_temperatures(const CanFrame& f) noexcept;
  /// The drive's time [ns] of a frame's T_first (FD) or T_low (classic), or false when the clock says stale
  /// (its `samples` counted stale).
  [[nodiscard]] bool drive_time(SampleClock& clock, std::uint32_t t_us, std::int64_t rx_ns, int samples,
                                std::int64_t& t_ns) noexcept;
  /// Accepts a sample at time t: rejects it as stale, else marks a pending gap. True if accepted.
  [[nodiscard]] bool accept(core::DriveSample& s) noexcept;

  DecoderCounters counters_;
  bool gap_pending_ = true;
  bool has_last_fd_counter_ = false;
  std::uint8_t last_fd_counter_ = 0;
  bool has_last_classic_counter_ = false;
  std::uint8_t last_classic_counter_ = 0;
  bool has_last_temperature_counter_ = false;
  std::uint8_t last_temperature_counter_ = 0;
  double winding_C_ = std::numeric_limits<double>::quiet_NaN();  ///< readings for the next delivered sample
  double coolant_C_ = std::numeric_limits<double>::quiet_NaN();
  bool has_time_ = false;
  std::int64_t last_time_us_ = 0;                    ///< unwrapped drive time of the last delivered sample
  SampleClock fd_clock_{32, false, 1e-6, 0.0};       ///< T_first: 32 bits of µs
  SampleClock classic_clock_{24, false, 1e-6, 0.0};  ///< T_low: 24 bits of µs

  // Classic assembly of one sample from five frames.
  std::uint8_t classic_counter_ = 0;
  std::uint8_t classic_mask_ = 0;
  bool classic_bad_ = false;
  std::array<std::int16_t, 3> classic_i_{};
  std::array<std::int16_t, 3> classic_u_{};
  std::uint16_t classic_theta_ = 0;
  std::int16_t classic_omega_ = 0;
  std::uint16_t classic_udc_ = 0;
  std::uint32_t classic_t_ = 0;
  std::uint8_t classic_status_ = 0;
};

}  // namespace rpem::can
