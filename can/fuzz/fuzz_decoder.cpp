// libFuzzer target for the telemetry decoder: the input is a stream of frames, each
//   [id low byte][id high byte][flags: bit0 FD, bit1 error, bit2 fix CRC, bits 3–7 r][len][len bytes of data]
// "fix CRC" re-protects the frame with its correct Data ID, so mutations reach past the E2E check; the
// frame is received r²·20 ms after the previous one (up to 19 s: past a classic frame's 16.8 s clock wrap).
// The decoder must never crash, never deliver a non-finite value (a temperature: NaN for no reading, else within
// the protocol's range), never deliver a sample whose time does not increase, and keep its counters consistent.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "rpem/can/decoder.hpp"
#include "rpem/can/e2e.hpp"
#include "rpem/can/protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rpem::can::TelemetryDecoder decoder;
  std::array<rpem::core::DriveSample, 3> out;
  std::int64_t last_t = INT64_MIN;
  std::size_t at = 0;
  std::uint64_t delivered = 0;
  std::int64_t rx_ns = 0;
  while (at + 4 <= size) {
    rpem::can::CanFrame f;
    f.id = static_cast<std::uint32_t>(data[at] | (data[at + 1] << 8)) & 0x7FF;
    f.fd = data[at + 2] & 1;
    f.error = data[at + 2] & 2;
    const std::int64_t r = data[at + 2] >> 3;
    rx_ns += r * r * 20'000'000;
    f.len = static_cast<std::uint8_t>(std::min<std::size_t>(data[at + 3], 64));
    at += 4;
    const std::size_t n = std::min<std::size_t>(f.len, size - at);
    for (std::size_t k = 0; k < n; ++k) f.data[k] = data[at + k];
    at += n;
    if ((data[at - n - 2] & 4) && f.len >= 3) {
      rpem::can::e2e_protect(f, rpem::can::protocol::data_id(f.id), rpem::can::e2e_counter(f));
    }
    const std::size_t got = decoder.decode(f, rx_ns, out);
    if (got > 3) std::abort();
    for (std::size_t k = 0; k < got; ++k) {
      const auto& s = out[k];
      if (!s.i_A.allFinite() || !s.u_V.allFinite() || !std::isfinite(s.theta_el_rad) || !std::isfinite(s.omega_el_rad_s) ||
          !std::isfinite(s.u_dc_V)) {
        std::abort();
      }
      for (double t_C : {s.t_winding_C, s.t_coolant_C}) {
        const double limit_C = (rpem::can::protocol::kSaturatedI16 - 1) * rpem::can::protocol::kTemperatureLsb_C;
        if (!std::isnan(t_C) && !(std::abs(t_C) <= limit_C + 1e-9)) std::abort();
      }
      if (s.t_ns <= last_t) std::abort();
      last_t = s.t_ns;
    }
    delivered += got;
  }
  if (decoder.counters().samples != delivered) std::abort();
  return 0;
}
