#include "rpem/can/bus_load.hpp"

#include <cmath>

#include "rpem/can/protocol.hpp"

namespace rpem::can {

double frame_time_s(bool fd, int n, const BusTiming& t) noexcept {
  if (!fd) {
    const int stuffed = 34 + 8 * n;
    const int bits = 47 + 8 * n + (stuffed - 1) / 4;
    return bits / t.nominal_bit_rate;
  }
  const int nominal_stuffed = 17;
  const int nominal_bits = nominal_stuffed + (nominal_stuffed - 1) / 4 + 13;
  const int crc = n > 16 ? 21 : 17;
  const int dynamic = 1 + 4 + 8 * n;  // ESI, DLC, data
  const int fixed_stuff = static_cast<int>(std::ceil((4 + crc) / 4.0)) + 1;
  const int data_bits = dynamic + (dynamic - 1) / 4 + 4 + crc + fixed_stuff;
  return nominal_bits / t.nominal_bit_rate + data_bits / t.data_bit_rate;
}

BusBudget telemetry_budget(bool fd, double rate, int per_frame, const BusTiming& t) noexcept {
  BusBudget b;
  if (fd) {
    b.frames_per_s = rate / per_frame;
    b.load = b.frames_per_s * frame_time_s(true, protocol::kFdLength, t);
  } else {
    b.frames_per_s = rate * protocol::kClassicFrames;
    b.load = b.frames_per_s * frame_time_s(false, protocol::kClassicLength, t);
  }
  return b;
}

}  // namespace rpem::can
