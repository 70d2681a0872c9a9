#include "rpem/can/vesc_firmware.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/can/e2e.hpp"

namespace rpem::can::vesc {
namespace {

/// A C cast of a float to int32 on the Cortex-M4 (VCVT.S32.F32): toward zero, saturating, NaN → 0.
std::int32_t arm_int32(double x) noexcept {
  if (std::isnan(x)) return 0;
  const double t = std::trunc(static_cast<double>(static_cast<float>(x)));
  if (t >= 2147483647.0) return 2147483647;
  if (t <= -2147483648.0) return -2147483647 - 1;
  return static_cast<std::int32_t>(t);
}
/// (int16_t)(float): the int32 conversion, then its low 16 bits.
std::int16_t arm_int16(double x) noexcept {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(static_cast<std::uint32_t>(arm_int32(x)) & 0xFFFF));
}

/// Big-endian appends in VESC's order (buffer.c, buffer_append_int16/int32/float16/float32). The value is
/// scaled in float, as VESC multiplies a float by the scale.
class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> out) noexcept : out_(out) {}
  void u8(std::uint8_t v) noexcept { put(&v, 1); }
  void i16(std::int16_t v) noexcept {
    const std::uint8_t b[2] = {static_cast<std::uint8_t>(static_cast<std::uint16_t>(v) >> 8), static_cast<std::uint8_t>(v)};
    put(b, 2);
  }
  void i32(std::int32_t v) noexcept {
    const auto u = static_cast<std::uint32_t>(v);
    const std::uint8_t b[4] = {static_cast<std::uint8_t>(u >> 24), static_cast<std::uint8_t>(u >> 16),
                               static_cast<std::uint8_t>(u >> 8), static_cast<std::uint8_t>(u)};
    put(b, 4);
  }
  void f16(double v, float scale) noexcept { i16(arm_int16(static_cast<float>(v) * scale)); }
  void f32(double v, float scale) noexcept { i32(arm_int32(static_cast<float>(v) * scale)); }
  [[nodiscard]] std::size_t size() const noexcept { return ok_ ? at_ : 0; }

 private:
  void put(const std::uint8_t* b, std::size_t n) noexcept {
    if (at_ + n > out_.size()) {
      ok_ = false;
      return;
    }
    std::copy(b, b + n, out_.begin() + static_cast<std::ptrdiff_t>(at_));
    at_ += n;
  }
  std::span<std::uint8_t> out_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

void write_field(Writer& w, Field f, const Values& v) noexcept {
  switch (f) {
    case kTempFet:
      w.f16(v.temp_fet_C, 1e1f);
      break;
    case kTempMotor:
      w.f16(v.temp_motor_C, 1e1f);
      break;
    case kCurrentMotor:
      w.f32(v.current_motor_A, 1e2f);
      break;
    case kCurrentIn:
      w.f32(v.current_in_A, 1e2f);
      break;
    case kId:
      w.f32(v.i_d_A, 1e2f);
      break;
    case kIq:
      w.f32(v.i_q_A, 1e2f);
      break;
    case kDuty:
      w.f16(v.duty, 1e3f);
      break;
    case kRpm:
      w.f32(v.erpm, 1e0f);
      break;
    case kVin:
      w.f16(v.v_in_V, 1e1f);
      break;
    case kAmpHours:
      w.f32(v.amp_hours_Ah, 1e4f);
      break;
    case kAmpHoursCharged:
      w.f32(v.amp_hours_charged_Ah, 1e4f);
      break;
    case kWattHours:
      w.f32(v.watt_hours_Wh, 1e4f);
      break;
    case kWattHoursCharged:
      w.f32(v.watt_hours_charged_Wh, 1e4f);
      break;
    case kTachometer:
      w.i32(v.tachometer);
      break;
    case kTachometerAbs:
      w.i32(v.tachometer_abs);
      break;
    case kFault:
      w.u8(v.fault);
      break;
    case kPidPos:
      w.f32(v.pid_pos_deg, 1e6f);
      break;
    case kControllerId:
      w.u8(v.controller_id);
      break;
    case kTempMos123:
      for (double t : v.temp_mos_C) w.f16(t, 1e1f);
      break;
    case kVd:
      w.f32(v.v_d_V, 1e3f);
      break;
    case kVq:
      w.f32(v.v_q_V, 1e3f);
      break;
    case kStatusBits:
      w.u8(v.status_bits);
      break;
    case kFieldCount:
      break;
  }
}

CanFrame frame(std::uint8_t node, Packet p, const std::uint8_t* data, std::size_t len) noexcept {
  CanFrame f;
  f.extended = true;
  f.id = extended_id(node, p);
  f.len = static_cast<std::uint8_t>(len);
  std::copy(data, data + len, f.data.begin());
  return f;
}

}  // namespace

std::optional<Request> parse_request(const CanFrame& f, std::uint8_t controller_id) noexcept {
  if (!f.extended || f.error || f.fd || f.len < 3) return std::nullopt;
  const auto addressee = static_cast<std::uint8_t>(f.id & 0xFF);
  if ((f.id >> 8) != static_cast<std::uint32_t>(Packet::kProcessShortBuffer)) return std::nullopt;
  if (addressee != controller_id && addressee != kBroadcastId) return std::nullopt;
  Request r;
  r.sender = f.data[0];
  r.commands_send = f.data[1];
  r.command = f.data[2];
  if (r.command == kCommGetValuesSelective && f.len >= 7) {
    r.mask =
        (std::uint32_t{f.data[3]} << 24) | (std::uint32_t{f.data[4]} << 16) | (std::uint32_t{f.data[5]} << 8) | f.data[6];
    r.has_mask = true;
  }
  return r;
}

double wire_float32(double value, float scale) noexcept {
  return arm_int32(static_cast<float>(value) * scale) / static_cast<double>(scale);
}

double wire_float16(double value, float scale) noexcept {
  return arm_int16(static_cast<float>(value) * scale) / static_cast<double>(scale);
}

std::size_t encode_values(const Values& v, std::uint32_t mask, std::span<std::uint8_t> out) noexcept {
  Writer w(out);
  w.u8(kCommGetValuesSelective);
  w.i32(static_cast<std::int32_t>(mask));
  for (int f = 0; f < kFieldCount; ++f) {
    if (mask & (std::uint32_t{1} << f)) write_field(w, static_cast<Field>(f), v);
  }
  return w.size();
}

std::size_t buffer_frames(std::uint8_t to_id, std::uint8_t from_id, std::uint8_t send, std::span<const std::uint8_t> payload,
                          std::span<CanFrame> out) noexcept {
  const std::size_t len = payload.size();
  if (len > 0xFFFF || out.size() < buffer_frame_count(len)) return 0;
  std::uint8_t b[8];
  std::size_t n = 0;
  if (len <= 6) {
    b[0] = from_id;
    b[1] = send;
    std::copy(payload.begin(), payload.end(), b + 2);
    out[n++] = frame(to_id, Packet::kProcessShortBuffer, b, len + 2);
    return n;
  }
  std::size_t i = 0;
  for (; i < len && i <= 255; i += 7) {  // FILL_RX_BUFFER: a one-byte offset
    const std::size_t chunk = std::min<std::size_t>(7, len - i);
    b[0] = static_cast<std::uint8_t>(i);
    std::copy_n(payload.begin() + static_cast<std::ptrdiff_t>(i), chunk, b + 1);
    out[n++] = frame(to_id, Packet::kFillRxBuffer, b, chunk + 1);
  }
  for (; i < len; i += 6) {  // FILL_RX_BUFFER_LONG: a two-byte offset
    const std::size_t chunk = std::min<std::size_t>(6, len - i);
    b[0] = static_cast<std::uint8_t>(i >> 8);
    b[1] = static_cast<std::uint8_t>(i);
    std::copy_n(payload.begin() + static_cast<std::ptrdiff_t>(i), chunk, b + 2);
    out[n++] = frame(to_id, Packet::kFillRxBufferLong, b, chunk + 2);
  }
  const std::uint16_t crc = crc16_ccitt_false(payload.data(), len, 0);  // crc.c, crc16: CRC-16/XMODEM
  b[0] = from_id;
  b[1] = send;
  b[2] = static_cast<std::uint8_t>(len >> 8);
  b[3] = static_cast<std::uint8_t>(len);
  b[4] = static_cast<std::uint8_t>(crc >> 8);
  b[5] = static_cast<std::uint8_t>(crc);
  out[n++] = frame(to_id, Packet::kProcessRxBuffer, b, 6);
  return n;
}

CanFrame status_frame(const Status& s) noexcept {
  std::uint8_t b[8] = {};
  Writer w(b);
  Packet p = Packet::kStatus1;
  switch (s.number) {
    case 1:
      w.i32(arm_int32(s.erpm));
      w.i16(arm_int16(static_cast<float>(s.current_A) * 1e1f));
      w.i16(arm_int16(static_cast<float>(s.duty) * 1e3f));
      break;
    case 2:
      p = Packet::kStatus2;
      w.i32(arm_int32(static_cast<float>(s.amp_hours_Ah) * 1e4f));
      w.i32(arm_int32(static_cast<float>(s.amp_hours_charged_Ah) * 1e4f));
      break;
    case 3:
      p = Packet::kStatus3;
      w.i32(arm_int32(static_cast<float>(s.watt_hours_Wh) * 1e4f));
      w.i32(arm_int32(static_cast<float>(s.watt_hours_charged_Wh) * 1e4f));
      break;
    case 4:
      p = Packet::kStatus4;
      w.i16(arm_int16(static_cast<float>(s.temp_fet_C) * 1e1f));
      w.i16(arm_int16(static_cast<float>(s.temp_motor_C) * 1e1f));
      w.i16(arm_int16(static_cast<float>(s.current_in_A) * 1e1f));
      w.i16(arm_int16(static_cast<float>(s.pid_pos_deg) * 50.0f));
      break;
    case 5:
      p = Packet::kStatus5;
      w.i32(s.tachometer);
      w.i16(arm_int16(static_cast<float>(s.v_in_V) * 1e1f));
      w.i16(0);  // reserved
      break;
    default:
      p = Packet::kStatus6;
      for (double a : s.adc_V) w.f16(a, 1e3f);
      break;
  }
  return frame(s.controller_id, p, b, w.size());
}

}  // namespace rpem::can::vesc
