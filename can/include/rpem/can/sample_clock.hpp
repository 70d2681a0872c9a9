#pragma once
// A drive's own sample time, read from a mapped signal (`t_sample`, docs/sources.md): the step between two
// samples is the drive's, not the bus's or the host's, so a burst of late frames (a loaded receiver, a
// starved VM, a gateway that buffers) still gives the estimator its true intervals.
//
// An integer signal wraps every 2^length counts; the number of wraps between two samples is the one that
// brings the drive's step nearest the receive times' step, so a silence longer than the wrap is still
// counted right (the receive clock only has to be good to half a wrap). A sample the drive stamped before
// the previous one (reordered, duplicated) is stale; kRestartAfterStale stale samples in a row, each after
// the one before, mean the drive's clock restarted, and the chain goes on from the previous time plus the
// receive step, as a gap (a clock that stopped stays stale).
// Pure: no I/O, no allocation, no exceptions.

#include <cstdint>

namespace rpem::can {

class SampleClock {
 public:
  static constexpr int kRestartAfterStale = 8;
  /// ~127 years (a Unix time fits until 2096); a larger time or step is no drive's clock, and t_ns could overflow.
  static constexpr double kMaxClockS = 4e9;

  enum class Step : std::uint8_t {
    kNext,   ///< after the previous sample: t_ns is its time
    kFirst,  ///< the first sample (or the first after a restart): t_ns starts the chain, a gap before it
    kStale,  ///< stamped at or before the previous sample, or no time at all: drop it
  };

  /// The map's t_sample signal: an unsigned integer of `length` bits (wrapping every 2^length counts) or an
  /// IEEE value (`is_float`: no wrap); seconds = raw · scale_s + offset_s, scale_s > 0.
  SampleClock(int length, bool is_float, double scale_s, double offset_s) noexcept;

  /// The signal's newest reading: its raw bits (integers) and its physical value [s] (floats).
  void on_value(std::uint64_t raw_bits, double value_s) noexcept;
  /// Closes a sample received at rx_ns: its drive time in t_ns (when not stale).
  [[nodiscard]] Step close(std::int64_t rx_ns, std::int64_t& t_ns) noexcept;

 private:
  /// The newest raw reading lies after `earlier_raw` by less than half a wrap (integers).
  [[nodiscard]] bool forward_of(std::uint64_t earlier_raw) const noexcept;
  void remember(std::int64_t rx_ns, std::int64_t t_ns) noexcept;

  bool is_float_ = false;
  std::int64_t span_ = 0;  ///< counts per wrap (integers); 0: no wrap (floats)
  double scale_s_ = 0.0;   ///< seconds per count
  double offset_s_ = 0.0;
  std::uint64_t raw_ = 0;  ///< the newest raw value (integers) …
  double value_s_ = 0.0;   ///< … or seconds (floats)
  std::uint64_t previous_raw_ = 0;
  double previous_value_s_ = 0.0;
  std::int64_t previous_t_ns_ = 0, previous_rx_ns_ = 0;
  int stale_run_ = 0;  ///< stale samples in a row, each after the one before (a clock that restarted)
  std::uint64_t stale_raw_ = 0;
  double stale_value_s_ = 0.0;
  bool started_ = false;
};

}  // namespace rpem::can
