#include "rpem/can/bus_load.hpp"

#include <array>
#include <cmath>

#include "rpem/can/protocol.hpp"
#include "rpem/can/signal_map.hpp"
#include "rpem/can/vesc_firmware.hpp"

namespace rpem::can {
namespace {

/// Worst-case stuff bits among n stuffable bits: one after the first 5 equal bits, then one per 4.
constexpr int stuff_bits(int n) noexcept { return (n - 1) / 4; }

}  // namespace

int fd_padded_length(int bytes) noexcept {
  if (bytes <= 8) return bytes;
  constexpr std::array<int, 7> kLengths = {12, 16, 20, 24, 32, 48, 64};
  for (int l : kLengths) {
    if (bytes <= l) return l;
  }
  return 64;
}

FrameBits frame_bits(const WireFrame& f) noexcept {
  constexpr int kTail = 13;  // CRC delimiter, ACK slot and delimiter, EOF (7), intermission (3)
  if (!f.fd) {
    const int stuffed = (f.extended ? 54 : 34) + 8 * f.payload_bytes;
    return {stuffed + stuff_bits(stuffed) + kTail, 0};
  }
  const int n = fd_padded_length(f.payload_bytes);
  const int nominal_stuffed = f.extended ? 36 : 17;
  const int crc = n > 16 ? 21 : 17;
  const int dynamic = 1 + 4 + 8 * n;  // ESI, DLC, data
  const int fixed_stuff = static_cast<int>(std::ceil((4 + crc) / 4.0)) + 1;
  return {nominal_stuffed + stuff_bits(nominal_stuffed) + kTail, dynamic + stuff_bits(dynamic) + 4 + crc + fixed_stuff};
}

double frame_time_s(const WireFrame& f, const BusTiming& t) noexcept {
  const FrameBits b = frame_bits(f);
  return b.nominal / t.nominal_bit_rate + b.data / t.data_bit_rate;
}

double frame_time_s(bool fd, int payload_bytes, const BusTiming& timing) noexcept {
  return frame_time_s(WireFrame{fd, false, payload_bytes, 1.0}, timing);
}

double time_per_sample_s(const Traffic& traffic, int drives, const BusTiming& t) noexcept {
  double drive_s = 0.0, bus_s = 0.0;
  for (const WireFrame& f : traffic.per_drive) drive_s += f.per_sample * frame_time_s(f, t);
  for (const WireFrame& f : traffic.per_bus) bus_s += f.per_sample * frame_time_s(f, t);
  return drives * drive_s + bus_s;
}

double max_sample_rate_Hz(const Traffic& traffic, int drives, double max_load, const BusTiming& t) noexcept {
  return max_load / time_per_sample_s(traffic, drives, t);
}

Traffic native_traffic(bool fd, int samples_per_fd_frame) {
  if (fd) return {"rpem native, FD", {{true, false, protocol::kFdLength, 1.0 / samples_per_fd_frame}}, {}};
  return {"rpem native, classic", {{false, false, protocol::kClassicLength, double{protocol::kClassicFrames}}}, {}};
}

Traffic vesc_poll_traffic(std::uint32_t mask) {
  Traffic t{"VESC poll + reply", {}, {}};
  const CanFrame poll = vesc::values_request(0, 0, mask);
  t.per_drive.push_back({false, true, poll.len, 1.0});
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload{};
  const std::size_t len = vesc::encode_values(vesc::Values{}, mask, payload);  // the layout's one definition
  std::vector<CanFrame> frames(vesc::buffer_frame_count(len));
  frames.resize(vesc::buffer_frames(0, 0, 1, {payload.data(), len}, frames));
  for (const CanFrame& f : frames) t.per_drive.push_back({false, true, f.len, 1.0});
  return t;
}

Traffic signal_map_traffic(const SignalMap& map, bool fd, bool sync) {
  Traffic t{"signal map " + map.name, {}, {}};
  for (const FrameSpec& f : map.frames) t.per_drive.push_back({fd, false, f.length, 1.0});
  if (sync) t.per_bus.push_back({false, false, 0, 1.0});  // CiA 301 SYNC, COB-ID 0x080, classic
  return t;
}

BusBudget telemetry_budget(bool fd, double sample_rate_Hz, int samples_per_fd_frame, const BusTiming& timing) {
  BusBudget b;
  const Traffic traffic = native_traffic(fd, samples_per_fd_frame);
  b.frames_per_s = sample_rate_Hz * traffic.per_drive.front().per_sample;
  b.load = sample_rate_Hz * time_per_sample_s(traffic, 1, timing);
  return b;
}

}  // namespace rpem::can
