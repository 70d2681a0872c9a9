// libFuzzer target for the VESC decoder (can/include/rpem/can/vesc.hpp). The input is a stream of records:
//   [0x00 | 2·k][a frame record, fuzz_frame.hpp]        a raw frame
//   [0x01 | 2·k][n][n bytes]                        a reply payload the harness splits into FILL_RX_BUFFER /
//                                                    _LONG frames and a PROCESS_RX_BUFFER with its true CRC,
//                                                    so mutations reach past the CRC into the reply parser
// The decoder must never crash, deliver only replies that carry the required mask with finite values, and
// keep its counters consistent with what it delivered.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_frame.hpp"
#include "rpem/can/e2e.hpp"
#include "rpem/can/vesc.hpp"

namespace {

namespace v = rpem::can::vesc;
constexpr std::uint8_t kController = 17, kOwn = 0x7D;

struct Harness {
  v::VescDecoder decoder{kController, kOwn};
  std::uint64_t values = 0, statuses = 0;

  void offer(const rpem::can::CanFrame& f) {
    switch (decoder.decode(f)) {
      case v::VescDecoder::Event::kValues: {
        ++values;
        const v::Values& x = decoder.values();
        if ((x.mask & v::kEstimatorMask) != v::kEstimatorMask) std::abort();
        const auto s = v::to_averaged_sample(x, 0, 1);
        if (!s.i_dq_A.allFinite() || !s.u_dq_V.allFinite() || !std::isfinite(s.omega_el_rad_s) || !std::isfinite(s.u_dc_V) ||
            !std::isfinite(s.t_winding_C) || !std::isfinite(s.t_drive_C)) {
          std::abort();
        }
        break;
      }
      case v::VescDecoder::Event::kStatus:
        ++statuses;
        if (decoder.status().number < 1 || decoder.status().number > 6) std::abort();
        break;
      case v::VescDecoder::Event::kNone:
        break;
    }
  }

  rpem::can::CanFrame frame(v::Packet p, const std::uint8_t* d, std::size_t n) {
    rpem::can::CanFrame f;
    f.extended = true;
    f.id = v::extended_id(kOwn, p);
    f.len = static_cast<std::uint8_t>(n);
    std::copy_n(d, n, f.data.begin());
    return f;
  }

  /// The frames VESC's comm_can_send_buffer sends for a payload (docs/can-vesc.md, "Buffer protocol").
  void reply(const std::uint8_t* p, std::size_t n) {
    std::uint8_t b[8];
    if (n <= 6) {
      b[0] = kController;
      b[1] = 1;
      std::copy_n(p, n, b + 2);
      offer(frame(v::Packet::kProcessShortBuffer, b, n + 2));
      return;
    }
    std::size_t i = 0;
    for (; i < n && i <= 255; i += 7) {
      b[0] = static_cast<std::uint8_t>(i);
      const std::size_t k = std::min<std::size_t>(7, n - i);
      std::copy_n(p + i, k, b + 1);
      offer(frame(v::Packet::kFillRxBuffer, b, k + 1));
    }
    for (; i < n; i += 6) {
      b[0] = static_cast<std::uint8_t>(i >> 8);
      b[1] = static_cast<std::uint8_t>(i);
      const std::size_t k = std::min<std::size_t>(6, n - i);
      std::copy_n(p + i, k, b + 2);
      offer(frame(v::Packet::kFillRxBufferLong, b, k + 2));
    }
    const std::uint16_t crc = rpem::can::crc16_ccitt_false(p, n, 0);
    const std::uint8_t end[6] = {kController,
                                 1,
                                 static_cast<std::uint8_t>(n >> 8),
                                 static_cast<std::uint8_t>(n),
                                 static_cast<std::uint8_t>(crc >> 8),
                                 static_cast<std::uint8_t>(crc)};
    offer(frame(v::Packet::kProcessRxBuffer, end, 6));
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Harness h;
  std::size_t at = 0;
  while (at < size) {
    const std::uint8_t kind = data[at++];
    if (kind & 1) {
      if (at >= size) break;
      const std::size_t stated = data[at++];
      const std::size_t n = std::min(stated, size - at);
      h.reply(data + at, n);
      at += n;
      continue;
    }
    rpem::can::CanFrame f;
    if (!rpem::can::fuzz::read_frame(data, size, at, f)) break;
    h.offer(f);
  }
  const v::VescCounters& c = h.decoder.counters();
  if (c.replies != h.values || c.statuses != h.statuses) std::abort();
  if (c.frames < c.replies + c.statuses) std::abort();
  return 0;
}
