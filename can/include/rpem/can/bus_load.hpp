#pragma once
// Bus budget: the duration of one telemetry frame on the wire with worst-case bit stuffing, and the
// resulting bus load (docs/can-protocol.md, "Bus budget").
//   classic (11-bit ID): 47 + 8·n bits, of which 34 + 8·n are stuffed (≤ 1 per 4)
//   CAN FD with bit-rate switch: nominal phase SOF…BRS (17 bits, stuffed) + CRC delimiter…IFS (13);
//   data phase ESI, DLC, data (stuffed), stuff count (4), CRC (17 or 21) with fixed stuff bits.

#include <cstdint>

namespace rpem::can {

struct BusTiming {
  double nominal_bit_rate = 1e6;  ///< arbitration phase [bit/s]
  double data_bit_rate = 5e6;     ///< FD data phase [bit/s]; ignored for classic frames
};

/// Worst-case duration of one frame with `payload_bytes` of data [s].
[[nodiscard]] double frame_time_s(bool fd, int payload_bytes, const BusTiming& timing) noexcept;

/// Telemetry frames per second and bus load for a sample rate.
struct BusBudget {
  double frames_per_s = 0.0;
  double load = 0.0;  ///< fraction of the bus time, worst-case stuffing
};
[[nodiscard]] BusBudget telemetry_budget(bool fd, double sample_rate_Hz, int samples_per_fd_frame,
                                         const BusTiming& timing) noexcept;

}  // namespace rpem::can
