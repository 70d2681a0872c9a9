#include "rpem/can/vesc.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "rpem/can/e2e.hpp"
#include "rpem/core/units.hpp"

namespace rpem::can::vesc {
namespace {

/// Big-endian reads in VESC's order (buffer.c, buffer_get_int16/int32); `ok` turns false past the end.
class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> d) noexcept : d_(d) {}
  [[nodiscard]] std::uint8_t u8() noexcept { return take(1) ? d_[at_ - 1] : 0; }
  [[nodiscard]] std::int16_t i16() noexcept {
    if (!take(2)) return 0;
    return static_cast<std::int16_t>((d_[at_ - 2] << 8) | d_[at_ - 1]);
  }
  [[nodiscard]] std::int32_t i32() noexcept {
    if (!take(4)) return 0;
    const std::uint32_t u = (std::uint32_t{d_[at_ - 4]} << 24) | (std::uint32_t{d_[at_ - 3]} << 16) |
                            (std::uint32_t{d_[at_ - 2]} << 8) | d_[at_ - 1];
    return static_cast<std::int32_t>(u);
  }
  /// buffer_get_float16/float32: the integer divided by the scale.
  [[nodiscard]] double f16(double scale) noexcept { return i16() / scale; }
  [[nodiscard]] double f32(double scale) noexcept { return i32() / scale; }
  [[nodiscard]] bool ok() const noexcept { return ok_; }
  [[nodiscard]] std::size_t left() const noexcept { return ok_ ? d_.size() - at_ : 0; }

 private:
  bool take(std::size_t n) noexcept {
    if (!ok_ || at_ + n > d_.size()) {
      ok_ = false;
      return false;
    }
    at_ += n;
    return true;
  }
  std::span<const std::uint8_t> d_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

void read_field(Reader& r, Field f, Values& v) noexcept {
  switch (f) {
    case kTempFet:
      v.temp_fet_C = r.f16(1e1);
      break;
    case kTempMotor:
      v.temp_motor_C = r.f16(1e1);
      break;
    case kCurrentMotor:
      v.current_motor_A = r.f32(1e2);
      break;
    case kCurrentIn:
      v.current_in_A = r.f32(1e2);
      break;
    case kId:
      v.i_d_A = r.f32(1e2);
      break;
    case kIq:
      v.i_q_A = r.f32(1e2);
      break;
    case kDuty:
      v.duty = r.f16(1e3);
      break;
    case kRpm:
      v.erpm = r.f32(1e0);
      break;
    case kVin:
      v.v_in_V = r.f16(1e1);
      break;
    case kAmpHours:
      v.amp_hours_Ah = r.f32(1e4);
      break;
    case kAmpHoursCharged:
      v.amp_hours_charged_Ah = r.f32(1e4);
      break;
    case kWattHours:
      v.watt_hours_Wh = r.f32(1e4);
      break;
    case kWattHoursCharged:
      v.watt_hours_charged_Wh = r.f32(1e4);
      break;
    case kTachometer:
      v.tachometer = r.i32();
      break;
    case kTachometerAbs:
      v.tachometer_abs = r.i32();
      break;
    case kFault:
      v.fault = r.u8();
      break;
    case kPidPos:
      v.pid_pos_deg = r.f32(1e6);
      break;
    case kControllerId:
      v.controller_id = r.u8();
      break;
    case kTempMos123:
      for (double& t : v.temp_mos_C) t = r.f16(1e1);
      break;
    case kVd:
      v.v_d_V = r.f32(1e3);
      break;
    case kVq:
      v.v_q_V = r.f32(1e3);
      break;
    case kStatusBits:
      v.status_bits = r.u8();
      break;
    case kFieldCount:
      break;
  }
}

/// The one rule both sides' kernel filters share: extended data frames (no remote frames) whose addressee, the
/// ID's low byte (comm_can.c: id | packet << 8), is `addressee`; with `packet`, only that packet, the whole
/// 29-bit ID then matched.
KernelFilter addressed_to(std::uint8_t addressee, std::optional<Packet> packet = std::nullopt) noexcept {
  if (!packet) return {kEffFlag | addressee, kEffFlag | kRtrFlag | 0xFFU};
  return {kEffFlag | extended_id(addressee, *packet), kEffFlag | kRtrFlag | kEffMask};
}

}  // namespace

CanFrame values_request(std::uint8_t controller_id, std::uint8_t own_id, std::uint32_t mask) noexcept {
  CanFrame f;
  f.extended = true;
  f.id = extended_id(controller_id, Packet::kProcessShortBuffer);
  f.len = 7;
  f.data[0] = own_id;  // whom the reply goes to
  f.data[1] = 0;       // commands_send 0: process and reply
  f.data[2] = kCommGetValuesSelective;
  for (int k = 0; k < 4; ++k) f.data[3 + k] = static_cast<std::uint8_t>(mask >> (24 - 8 * k));
  return f;
}

ParseResult parse_values(std::span<const std::uint8_t> payload, Values& out) noexcept {
  if (payload.empty() || payload[0] != kCommGetValuesSelective) return ParseResult::kNotValues;
  Reader r(payload.subspan(1));
  Values v;
  v.mask = static_cast<std::uint32_t>(r.i32());
  for (int f = 0; f < kFieldCount && r.ok(); ++f) {
    if (v.mask & (std::uint32_t{1} << f)) read_field(r, static_cast<Field>(f), v);
  }
  if (!r.ok()) return ParseResult::kShort;
  if (r.left() != 0) return ParseResult::kTrailing;
  out = v;
  return ParseResult::kOk;
}

std::array<KernelFilter, 3> kernel_filters(std::uint8_t controller_id, std::uint8_t host_id) noexcept {
  return {{addressed_to(host_id), addressed_to(controller_id), addressed_to(kBroadcastId)}};
}

std::array<KernelFilter, 2> controller_kernel_filters(std::uint8_t controller_id) noexcept {
  return {
      {addressed_to(controller_id, Packet::kProcessShortBuffer), addressed_to(kBroadcastId, Packet::kProcessShortBuffer)}};
}

VescDecoder::VescDecoder(std::uint8_t controller_id, std::uint8_t own_id, std::uint32_t required_mask) noexcept
    : controller_id_(controller_id), own_id_(own_id), required_mask_(required_mask) {}

VescDecoder::Event VescDecoder::decode(const CanFrame& f) noexcept {
  ++counters_.frames;
  if (f.error) {
    ++counters_.error_frames;
    return Event::kNone;
  }
  if (!f.extended || f.fd || f.id > 0x1FFFFFFF) {
    ++counters_.foreign;
    return Event::kNone;
  }
  const std::uint8_t addressee = f.id & 0xFF;
  const std::uint32_t packet = f.id >> 8;
  if (packet > 0xFF) {
    ++counters_.unknown_packet;
    return Event::kNone;
  }
  switch (static_cast<Packet>(packet)) {
    case Packet::kFillRxBuffer:
    case Packet::kFillRxBufferLong:
    case Packet::kProcessRxBuffer:
    case Packet::kProcessShortBuffer:
      if (addressee != own_id_) {
        ++counters_.foreign;
        return Event::kNone;
      }
      break;
    case Packet::kStatus1:
    case Packet::kStatus2:
    case Packet::kStatus3:
    case Packet::kStatus4:
    case Packet::kStatus5:
    case Packet::kStatus6:
      // A status carries its sender's id.
      if (addressee != controller_id_) {
        ++counters_.foreign;
        return Event::kNone;
      }
      return decode_status(f, static_cast<Packet>(packet));
    default:
      ++counters_.unknown_packet;
      return Event::kNone;
  }
  const std::span<const std::uint8_t> d(f.data.data(), f.len);
  switch (static_cast<Packet>(packet)) {
    case Packet::kFillRxBuffer:
      return fill(f, 1);
    case Packet::kFillRxBufferLong:
      return fill(f, 2);
    case Packet::kProcessRxBuffer: {
      // [sender][commands_send][len hi][len lo][crc hi][crc lo]
      if (f.len < 6) {
        ++counters_.wrong_length;
        return Event::kNone;
      }
      if (d[0] != controller_id_) {
        ++counters_.foreign;
        return Event::kNone;
      }
      const std::size_t len = (std::size_t{d[2]} << 8) | d[3];
      const std::uint16_t crc = static_cast<std::uint16_t>((d[4] << 8) | d[5]);
      const std::size_t filled = fill_;
      fill_ = 0;
      if (len != filled) {
        ++counters_.length_mismatch;
        return Event::kNone;
      }
      // CRC-16/XMODEM (crc.c, crc16: table of polynomial 0x1021, initial value 0).
      if (crc16_ccitt_false(buffer_.data(), len, 0) != crc) {
        ++counters_.crc_error;
        return Event::kNone;
      }
      return process(std::span<const std::uint8_t>(buffer_.data(), len));
    }
    case Packet::kProcessShortBuffer:
      // [sender][commands_send][payload ≤ 6]
      if (f.len < 3) {
        ++counters_.wrong_length;
        return Event::kNone;
      }
      if (d[0] != controller_id_) {
        ++counters_.foreign;
        return Event::kNone;
      }
      return process(d.subspan(2));
    default:
      return Event::kNone;
  }
}

VescDecoder::Event VescDecoder::fill(const CanFrame& f, std::size_t header) noexcept {
  // FILL_RX_BUFFER: [offset][≤ 7 bytes]; FILL_RX_BUFFER_LONG: [offset hi][offset lo][≤ 6 bytes].
  if (f.len <= header) {
    ++counters_.wrong_length;
    return Event::kNone;
  }
  const std::size_t offset = header == 1 ? f.data[0] : (std::size_t{f.data[0]} << 8) | f.data[1];
  const std::size_t n = f.len - header;
  if (offset == 0) {
    fill_ = 0;  // a new buffer (VESC starts one at offset 0 too)
  } else if (offset != fill_) {
    ++counters_.out_of_order;
    fill_ = 0;
    return Event::kNone;
  }
  if (offset + n > buffer_.size()) {
    ++counters_.overflow;
    fill_ = 0;
    return Event::kNone;
  }
  std::copy_n(f.data.begin() + static_cast<std::ptrdiff_t>(header), n,
              buffer_.begin() + static_cast<std::ptrdiff_t>(offset));
  fill_ = offset + n;
  return Event::kNone;
}

VescDecoder::Event VescDecoder::process(std::span<const std::uint8_t> payload) noexcept {
  Values v;
  switch (parse_values(payload, v)) {
    case ParseResult::kNotValues:
      ++counters_.not_values;
      return Event::kNone;
    case ParseResult::kShort:
      ++counters_.short_reply;
      return Event::kNone;
    case ParseResult::kTrailing:
      ++counters_.trailing;
      return Event::kNone;
    case ParseResult::kOk:
      break;
  }
  if ((v.mask & required_mask_) != required_mask_) {
    ++counters_.wrong_mask;
    return Event::kNone;
  }
  values_ = v;
  ++counters_.replies;
  return Event::kValues;
}

VescDecoder::Event VescDecoder::decode_status(const CanFrame& f, Packet p) noexcept {
  // Every status is 8 bytes (comm_can.c, comm_can_send_status1…6).
  if (f.len < 8) {
    ++counters_.wrong_length;
    return Event::kNone;
  }
  Reader r(std::span<const std::uint8_t>(f.data.data(), f.len));
  Status s;
  s.controller_id = controller_id_;
  switch (p) {
    case Packet::kStatus1:
      s.number = 1;
      s.erpm = r.i32();
      s.current_A = r.f16(1e1);
      s.duty = r.f16(1e3);
      break;
    case Packet::kStatus2:
      s.number = 2;
      s.amp_hours_Ah = r.f32(1e4);
      s.amp_hours_charged_Ah = r.f32(1e4);
      break;
    case Packet::kStatus3:
      s.number = 3;
      s.watt_hours_Wh = r.f32(1e4);
      s.watt_hours_charged_Wh = r.f32(1e4);
      break;
    case Packet::kStatus4:
      s.number = 4;
      s.temp_fet_C = r.f16(1e1);
      s.temp_motor_C = r.f16(1e1);
      s.current_in_A = r.f16(1e1);
      s.pid_pos_deg = r.f16(50.0);
      break;
    case Packet::kStatus5:
      s.number = 5;
      s.tachometer = r.i32();
      s.v_in_V = r.f16(1e1);
      break;
    case Packet::kStatus6:
      s.number = 6;
      for (double& a : s.adc_V) a = r.f16(1e3);
      break;
    default:
      return Event::kNone;
  }
  status_ = s;
  ++counters_.statuses;
  return Event::kStatus;
}

core::AveragedSample to_averaged_sample(const Values& v, std::int64_t t_start_ns, std::int64_t t_ns) noexcept {
  core::AveragedSample s;
  s.t_start_ns = t_start_ns;
  s.t_ns = t_ns;
  s.i_dq_A = {v.i_d_A, v.i_q_A};
  s.u_dq_V = {v.v_d_V, v.v_q_V};
  s.omega_el_rad_s = core::rpm_to_rad_s(v.erpm);
  s.u_dc_V = v.v_in_V;
  s.t_winding_C = is_no_motor_reading(v.temp_motor_C) ? kNaN : v.temp_motor_C;
  s.t_drive_C = v.temp_fet_C;
  return s;
}

}  // namespace rpem::can::vesc
