#pragma once
// Bus budget: the duration of a frame on the wire with worst-case bit stuffing, the bus load of a
// traffic pattern, and the highest per-drive sample rate N drives can share under a load limit
// (docs/can-protocol.md, "Bus budget"; docs/benchmarks.md, "Several drives per bus"). Bit counts of
// ISO 11898-1 (worst case: a stuff bit after every 4 stuffable bits after the first, (n − 1)/4):
//   classic, 11-bit ID: 47 + 8·n bits, of which 34 + 8·n are stuffed
//   classic, 29-bit ID: 67 + 8·n bits, of which 54 + 8·n are stuffed (SRR, IDE, 18 more ID bits, r1)
//   CAN FD with bit-rate switch: nominal phase SOF…BRS (17 bits, 11-bit ID; 36, 29-bit ID; stuffed) and
//   CRC delimiter…IFS (13); data phase ESI, DLC, data (stuffed), stuff count (4), CRC (17 or 21) with
//   its fixed stuff bits. An FD payload is padded to the next valid length (12, 16, 20, 24, 32, 48, 64).

#include <cstdint>
#include <string>
#include <vector>

namespace rpem::can {

struct SignalMap;

struct BusTiming {
  double nominal_bit_rate = 1e6;  ///< arbitration phase [bit/s]
  double data_bit_rate = 5e6;     ///< FD data phase [bit/s]; ignored for classic frames
};

/// Worst-case duration of one frame with `payload_bytes` of data [s] (11-bit ID).
[[nodiscard]] double frame_time_s(bool fd, int payload_bytes, const BusTiming& timing) noexcept;

/// A frame on the wire and how many of it a sample takes.
struct WireFrame {
  bool fd = false;
  bool extended = false;  ///< 29-bit identifier
  int payload_bytes = 8;
  double per_sample = 1.0;  ///< frames per sample (1/3: three samples share one frame)
};

/// Bits of one frame, worst-case stuffing, in the nominal and the data phase (classic: all nominal).
struct FrameBits {
  int nominal = 0;
  int data = 0;
};
[[nodiscard]] FrameBits frame_bits(const WireFrame& f) noexcept;
[[nodiscard]] double frame_time_s(const WireFrame& f, const BusTiming& timing) noexcept;
/// The payload an FD frame actually carries for `bytes` (the next valid FD data length).
[[nodiscard]] int fd_padded_length(int bytes) noexcept;

/// What a source puts on the bus per sample: frames of each drive, and frames once per sample period
/// for the whole bus (a CANopen SYNC).
struct Traffic {
  std::string name;
  std::vector<WireFrame> per_drive;
  std::vector<WireFrame> per_bus;
};

/// Bus time per sample period for `drives` drives [s].
[[nodiscard]] double time_per_sample_s(const Traffic& t, int drives, const BusTiming& timing) noexcept;
/// The highest per-drive sample rate `drives` drives can share at `max_load` [Hz].
[[nodiscard]] double max_sample_rate_Hz(const Traffic& t, int drives, double max_load, const BusTiming& timing) noexcept;

/// rpem's native telemetry (docs/can-protocol.md): five 8-byte classic frames per sample, or one 64-byte
/// FD frame per `samples_per_fd_frame` samples.
[[nodiscard]] Traffic native_traffic(bool fd, int samples_per_fd_frame);
/// VESC polled with COMM_GET_VALUES_SELECTIVE (docs/can-vesc.md): the 7-byte poll and the reply of
/// `mask` in the buffer protocol — classic frames with 29-bit IDs whatever the bus (VESC's CAN is classic).
[[nodiscard]] Traffic vesc_poll_traffic(std::uint32_t mask);
/// A signal map's frames, one each per sample (as FD frames with bit-rate switch if `fd`), plus a SYNC
/// (11-bit ID 0x080, no data) per sample period for the bus if `sync`.
[[nodiscard]] Traffic signal_map_traffic(const SignalMap& map, bool fd, bool sync);

/// Telemetry frames per second and bus load for a sample rate (native telemetry, one drive).
struct BusBudget {
  double frames_per_s = 0.0;
  double load = 0.0;  ///< fraction of the bus time, worst-case stuffing
};
[[nodiscard]] BusBudget telemetry_budget(bool fd, double sample_rate_Hz, int samples_per_fd_frame, const BusTiming& timing);

}  // namespace rpem::can
