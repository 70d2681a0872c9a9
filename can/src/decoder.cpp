#include "rpem/can/decoder.hpp"

#include <utility>

#include "rpem/can/e2e.hpp"
#include "rpem/can/protocol.hpp"

namespace rpem::can {

namespace p = protocol;

namespace {

enum class Value { kOk, kSaturated, kInvalid };

Value check(std::int16_t raw) noexcept {
  if (raw == p::kInvalidI16) return Value::kInvalid;
  if (raw == p::kSaturatedI16 || raw == -p::kSaturatedI16) return Value::kSaturated;
  return Value::kOk;
}
Value check_u16(std::uint16_t raw) noexcept {
  if (raw == p::kInvalidU16) return Value::kInvalid;
  if (raw == p::kSaturatedU16) return Value::kSaturated;
  return Value::kOk;
}

/// Builds a sample from raw fields; false (and the kind counted) if any field is unusable.
bool build(const std::array<std::int16_t, 3>& i, const std::array<std::int16_t, 3>& u, std::uint16_t theta,
           std::int16_t omega, std::uint16_t u_dc, std::uint8_t status, DecoderCounters& c, core::DriveSample& s) noexcept {
  Value worst = check_u16(u_dc);
  auto fold = [&](Value v) {
    if (v == Value::kInvalid || (v == Value::kSaturated && worst == Value::kOk)) worst = v;
  };
  for (int k = 0; k < 3; ++k) {
    fold(check(i[static_cast<std::size_t>(k)]));
    fold(check(u[static_cast<std::size_t>(k)]));
  }
  fold(check(omega));
  if (status & p::status::kAngleInvalid) worst = Value::kInvalid;
  if (worst == Value::kInvalid) {
    ++c.invalid_value;
    return false;
  }
  if (worst == Value::kSaturated) {
    ++c.out_of_range;
    return false;
  }
  s.current_frame = core::Frame::kAbc;
  s.voltage_frame = core::Frame::kAbc;
  for (int k = 0; k < 3; ++k) {
    s.i_A[k] = i[static_cast<std::size_t>(k)] * p::kCurrentLsb_A;
    s.u_V[k] = u[static_cast<std::size_t>(k)] * p::kVoltageLsb_V;
  }
  s.theta_el_rad = p::angle_of(theta);
  s.omega_el_rad_s = omega * p::kSpeedLsb_rad_s;
  s.u_dc_V = u_dc * p::kDcLinkLsb_V;
  return true;
}

}  // namespace

void TelemetryDecoder::resynchronize() noexcept {
  gap_pending_ = true;
  has_last_fd_counter_ = false;
  has_last_classic_counter_ = false;
  has_last_temperature_counter_ = false;
  classic_mask_ = 0;
  winding_C_ = coolant_C_ = std::numeric_limits<double>::quiet_NaN();
}

TelemetryDecoder::Sequence TelemetryDecoder::check_sequence(std::uint8_t counter, bool& has_last,
                                                            std::uint8_t& last) noexcept {
  if (!has_last) {
    has_last = true;
    last = counter;
    return Sequence::kFirst;
  }
  const auto delta = static_cast<std::uint8_t>(counter - last);
  if (delta == 0) return Sequence::kDuplicate;
  if (delta > 128) return Sequence::kReordered;
  last = counter;
  if (delta == 1) return Sequence::kNext;
  counters_.frames_lost += delta - 1U;
  return Sequence::kLost;
}

bool TelemetryDecoder::drive_time(SampleClock& clock, std::uint32_t t_us, std::int64_t rx_ns, int samples,
                                  std::int64_t& t_ns) noexcept {
  clock.on_value(t_us, 0.0);
  switch (clock.close(rx_ns, t_ns)) {
    case SampleClock::Step::kStale:
      counters_.stale += static_cast<std::uint64_t>(samples);
      gap_pending_ = true;
      return false;
    case SampleClock::Step::kFirst:  // the first, or the drive's clock restarted
      gap_pending_ = true;
      return true;
    case SampleClock::Step::kNext:
      return true;
  }
  return false;
}

bool TelemetryDecoder::accept(core::DriveSample& s) noexcept {
  const std::int64_t t_us = s.t_ns / 1000;
  if (has_time_ && t_us <= last_time_us_) {
    ++counters_.stale;
    gap_pending_ = true;
    return false;
  }
  has_time_ = true;
  last_time_us_ = t_us;
  s.t_winding_C = std::exchange(winding_C_, std::numeric_limits<double>::quiet_NaN());
  s.t_coolant_C = std::exchange(coolant_C_, std::numeric_limits<double>::quiet_NaN());
  s.gap_before = gap_pending_;
  if (gap_pending_) ++counters_.gaps;
  gap_pending_ = false;
  ++counters_.samples;
  return true;
}

std::size_t TelemetryDecoder::decode(const CanFrame& f, std::int64_t rx_ns, std::span<core::DriveSample> out) noexcept {
  ++counters_.frames;
  if (f.error) return 0;  // error frames are counted by the transport
  if (f.extended) {       // telemetry uses standard IDs only; an extended one (e.g. a VESC's) is not ours
    ++counters_.unknown_id;
    return 0;
  }
  if (f.id == p::kFdId) return decode_fd(f, rx_ns, out);
  if (f.id >= p::kClassicFirstId && f.id < p::kClassicFirstId + p::kClassicFrames) return decode_classic(f, rx_ns, out);
  if (f.id == p::kTemperatureId) {
    decode_temperatures(f);
    return 0;
  }
  ++counters_.unknown_id;
  return 0;
}

void TelemetryDecoder::decode_temperatures(const CanFrame& f) noexcept {
  if (f.fd || f.len != p::kClassicLength) {
    ++counters_.wrong_dlc;
    return;
  }
  if (!e2e_check(f, p::data_id(f.id))) {  // a temperature is no sample: a bad one leaves the samples' stream whole
    ++counters_.crc_error;
    return;
  }
  switch (check_sequence(e2e_counter(f), has_last_temperature_counter_, last_temperature_counter_)) {
    case Sequence::kDuplicate:
      ++counters_.duplicated;
      return;
    case Sequence::kReordered:
      ++counters_.reordered;
      return;
    case Sequence::kFirst:
    case Sequence::kNext:
    case Sequence::kLost:  // counted; the readings stand on their own
      break;
  }
  // The no-valid-value code is a sensor the drive has not (or has no reading of): NaN, nothing counted.
  auto reading = [&](int at, double held) {
    const std::int16_t raw = p::get_i16(f, at);
    switch (check(raw)) {
      case Value::kOk:
        return raw * p::kTemperatureLsb_C;
      case Value::kSaturated:
        ++counters_.out_of_range;
        return held;
      case Value::kInvalid:
        return held;
    }
    return held;
  };
  winding_C_ = reading(3, winding_C_);
  coolant_C_ = reading(5, coolant_C_);
}

std::size_t TelemetryDecoder::decode_fd(const CanFrame& f, std::int64_t rx_ns, std::span<core::DriveSample> out) noexcept {
  if (!f.fd || f.len != p::kFdLength) {
    ++counters_.wrong_dlc;
    return 0;
  }
  if (!e2e_check(f, p::data_id(f.id))) {
    ++counters_.crc_error;
    gap_pending_ = true;
    return 0;
  }
  if ((f.data[3] >> 4) != p::kVersion) {
    ++counters_.bad_version;
    return 0;
  }
  const int n = f.data[3] & 0x0F;
  if (n < 1 || n > p::kFdMaxSamples || out.size() < static_cast<std::size_t>(n)) {
    ++counters_.wrong_dlc;
    return 0;
  }
  switch (check_sequence(e2e_counter(f), has_last_fd_counter_, last_fd_counter_)) {
    case Sequence::kDuplicate:
      ++counters_.duplicated;
      return 0;
    case Sequence::kReordered:
      ++counters_.reordered;
      return 0;
    case Sequence::kLost:
      gap_pending_ = true;
      break;
    case Sequence::kFirst:
    case Sequence::kNext:
      break;
  }
  const std::uint16_t period_us = p::get_u16(f, 8);
  if (n > 1 && period_us == 0) {
    ++counters_.invalid_value;
    gap_pending_ = true;
    return 0;
  }
  std::int64_t t0_ns = 0;
  if (!drive_time(fd_clock_, p::get_u32(f, 4), rx_ns, n, t0_ns)) return 0;
  const std::uint16_t u_dc = p::get_u16(f, 10);
  const std::uint8_t status = f.data[12];
  std::size_t delivered = 0;
  for (int j = 0; j < n; ++j) {
    const int at = p::kFdHeaderBytes + j * p::kFdSampleBytes;
    const std::array<std::int16_t, 3> i = {p::get_i16(f, at), p::get_i16(f, at + 2), p::get_i16(f, at + 4)};
    const std::array<std::int16_t, 3> u = {p::get_i16(f, at + 6), p::get_i16(f, at + 8), p::get_i16(f, at + 10)};
    core::DriveSample& s = out[delivered];
    s = core::DriveSample{};
    s.t_ns = t0_ns + static_cast<std::int64_t>(j) * period_us * 1000;
    if (!build(i, u, p::get_u16(f, at + 12), p::get_i16(f, at + 14), u_dc, status, counters_, s)) {
      gap_pending_ = true;
      continue;
    }
    if (accept(s)) ++delivered;
  }
  return delivered;
}

std::size_t TelemetryDecoder::decode_classic(const CanFrame& f, std::int64_t rx_ns,
                                             std::span<core::DriveSample> out) noexcept {
  if (f.fd || f.len != p::kClassicLength) {
    ++counters_.wrong_dlc;
    return 0;
  }
  if (!e2e_check(f, p::data_id(f.id))) {
    ++counters_.crc_error;
    classic_bad_ = true;
    return 0;
  }
  const int part = static_cast<int>(f.id - p::kClassicFirstId);
  const std::uint8_t counter = e2e_counter(f);
  if (part == 0) {
    // A new sample begins: whatever was being assembled is incomplete.
    if (classic_mask_ != 0) {
      ++counters_.incomplete;
      gap_pending_ = true;
    }
    switch (check_sequence(counter, has_last_classic_counter_, last_classic_counter_)) {
      case Sequence::kDuplicate:
        ++counters_.duplicated;
        classic_mask_ = 0;
        return 0;
      case Sequence::kReordered:
        ++counters_.reordered;
        classic_mask_ = 0;
        return 0;
      case Sequence::kLost:
        gap_pending_ = true;
        break;
      case Sequence::kFirst:
      case Sequence::kNext:
        break;
    }
    classic_counter_ = counter;
    classic_mask_ = 0;
    classic_bad_ = false;
  } else if (classic_mask_ == 0 || counter != classic_counter_ || (classic_mask_ & (1U << part))) {
    // A part without its start, of another sample, or twice.
    if (counter == classic_counter_ && (classic_mask_ & (1U << part))) {
      ++counters_.duplicated;
    } else {
      ++counters_.reordered;
    }
    return 0;
  }
  switch (part) {
    case 0:
      classic_i_[0] = p::get_i16(f, 3);
      classic_i_[1] = p::get_i16(f, 5);
      classic_status_ = f.data[7];
      break;
    case 1:
      classic_i_[2] = p::get_i16(f, 3);
      classic_theta_ = p::get_u16(f, 5);
      break;
    case 2:
      classic_u_[0] = p::get_i16(f, 3);
      classic_u_[1] = p::get_i16(f, 5);
      break;
    case 3:
      classic_u_[2] = p::get_i16(f, 3);
      classic_omega_ = p::get_i16(f, 5);
      break;
    default:
      classic_udc_ = p::get_u16(f, 3);
      classic_t_ = static_cast<std::uint32_t>(f.data[5] | (f.data[6] << 8) | (f.data[7] << 16));
      break;
  }
  classic_mask_ = static_cast<std::uint8_t>(classic_mask_ | (1U << part));
  if (classic_mask_ != (1U << p::kClassicFrames) - 1U) return 0;
  classic_mask_ = 0;
  if (classic_bad_ || out.empty()) {
    gap_pending_ = true;
    return 0;
  }
  core::DriveSample& s = out[0];
  s = core::DriveSample{};
  if (!drive_time(classic_clock_, classic_t_, rx_ns, 1, s.t_ns)) return 0;
  if (!build(classic_i_, classic_u_, classic_theta_, classic_omega_, classic_udc_, classic_status_, counters_, s)) {
    gap_pending_ = true;
    return 0;
  }
  return accept(s) ? 1 : 0;
}

}  // namespace rpem::can
