#pragma once
// VESC (vedderb/bldc) over CAN, the receiver's side: the COMM_GET_VALUES_SELECTIVE poll, the multi-frame
// buffer protocol its replies travel in, the reply's fields with VESC's scalings, and the status broadcasts
// 1–6. Every ID, layout and scaling is documented in docs/can-vesc.md with the file and function of VESC's
// firmware it comes from. Pure: no I/O, no allocation, no exceptions.
//
//   extended ID = controller id | (CAN_PACKET_ID << 8)       (comm_can.c, comm_can_send_buffer)
//   numbers big endian; "float16/float32" are int16/int32 of value·scale (buffer.c)

#include <array>
#include <cstdint>
#include <limits>
#include <span>

#include "rpem/can/frame.hpp"
#include "rpem/can/kernel_filter.hpp"
#include "rpem/core/averaged_sample.hpp"

namespace rpem::can::vesc {

/// CAN_PACKET_ID (datatypes.h): the packets this decoder reads or sends.
enum class Packet : std::uint8_t {
  kFillRxBuffer = 5,
  kFillRxBufferLong = 6,
  kProcessRxBuffer = 7,
  kProcessShortBuffer = 8,
  kStatus1 = 9,
  kStatus2 = 14,
  kStatus3 = 15,
  kStatus4 = 16,
  kStatus5 = 27,
  kStatus6 = 58,
};

/// COMM_PACKET_ID COMM_GET_VALUES_SELECTIVE (datatypes.h).
inline constexpr std::uint8_t kCommGetValuesSelective = 50;
/// The broadcast controller id (comm_can.c, decode_msg: "id == 255").
inline constexpr std::uint8_t kBroadcastId = 255;

/// The kernel filters for a poller `host_id` of `controller_id` (SocketCanChannel::Options::filters): extended
/// data frames whose low byte is the host (replies to it), the controller (its status broadcasts, and other
/// nodes' commands to it: a second poller's reads) or the broadcast id (commands to every controller). Other
/// controllers' statuses, replies to other hosts and standard frames stay in the kernel.
[[nodiscard]] std::array<KernelFilter, 3> kernel_filters(std::uint8_t controller_id, std::uint8_t host_id) noexcept;

/// The kernel filters for a *controller* `controller_id` (an emulated VESC, tools/rpem/vesc_emulator.cpp):
/// extended data frames of the one packet it handles, PROCESS_SHORT_BUFFER (vesc_firmware.hpp, parse_request),
/// addressed to it or to every controller (kBroadcastId; comm_can.c, decode_msg). The whole 29-bit ID is
/// matched, so other controllers' commands, every reply and status, and ids above VESC's 16 bits stay in the
/// kernel: twelve controllers on one bus are each woken only by their own polls.
[[nodiscard]] std::array<KernelFilter, 2> controller_kernel_filters(std::uint8_t controller_id) noexcept;

/// Bits of the COMM_GET_VALUES_SELECTIVE mask (commands.c, commands_process_packet), in reply order.
enum Field : int {
  kTempFet = 0,
  kTempMotor = 1,
  kCurrentMotor = 2,
  kCurrentIn = 3,
  kId = 4,
  kIq = 5,
  kDuty = 6,
  kRpm = 7,
  kVin = 8,
  kAmpHours = 9,
  kAmpHoursCharged = 10,
  kWattHours = 11,
  kWattHoursCharged = 12,
  kTachometer = 13,
  kTachometerAbs = 14,
  kFault = 15,
  kPidPos = 16,
  kControllerId = 17,
  kTempMos123 = 18,
  kVd = 19,
  kVq = 20,
  kStatusBits = 21,
  kFieldCount = 22,
};

[[nodiscard]] constexpr std::uint32_t bit(Field f) noexcept { return std::uint32_t{1} << f; }

/// What the estimator needs: i_d, i_q, v_d, v_q (averages since the previous read), ERPM, V_in, FET and
/// motor temperature.
inline constexpr std::uint32_t kEstimatorMask =
    bit(kTempFet) | bit(kTempMotor) | bit(kId) | bit(kIq) | bit(kRpm) | bit(kVin) | bit(kVd) | bit(kVq);
/// The estimator's fields and the tachometer, for a drive whose speed is counted (a Hall drive at a crawl).
inline constexpr std::uint32_t kCountingMask = kEstimatorMask | bit(kTachometer);
/// The tachometer's step: a 60° sector of the angle in use (mcpwm_foc.c, "Update tachometer"), six per turn.
inline constexpr double kTachometerStepRad = core::kPi / 3.0;

[[nodiscard]] constexpr std::uint32_t extended_id(std::uint8_t controller_id, Packet p) noexcept {
  return controller_id | (static_cast<std::uint32_t>(p) << 8);
}

/// The poll: COMM_GET_VALUES_SELECTIVE with `mask`, as a short buffer to `controller_id` from `own_id`
/// asking for a reply (commands_send = 0).
[[nodiscard]] CanFrame values_request(std::uint8_t controller_id, std::uint8_t own_id, std::uint32_t mask) noexcept;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The firmware's default PLL gains, whose speed the reply's ERPM is (foc_pll_kp [1/s], foc_pll_ki [1/s²]:
/// MCCONF_FOC_PLL_KP, MCCONF_FOC_PLL_KI in vedderb/bldc motor/mcconf_default.h at b9d287b3; the PLL:
/// motor/foc_math.c, foc_pll_run). Its speed lags a ramp by k_p/k_i = 66.7 ms (docs/derivations.md §13).
inline constexpr double kDefaultPllKp = 2000.0;
inline constexpr double kDefaultPllKi = 30000.0;

/// The motor temperature the firmware reports where it has no reading of the motor's sensor: a reading that is NaN,
/// infinite, above 600 °C or below −200 °C (an open or shorted NTC, or none fitted: the NTC formula's −273.15) is
/// replaced by −100 °C before its low-pass filter (vedderb/bldc motor/mc_interface.c, update_override_limits), and
/// the reply and status 4 carry it as float16 ×10: exactly −1000. The VESC Tool log map says the same
/// (config/log-maps/vesc-tool.yaml, temp_motor's no_reading; a test holds the two equal).
inline constexpr double kNoMotorReading_C = -100.0;
[[nodiscard]] constexpr bool is_no_motor_reading(double temp_motor_C) noexcept {
  return temp_motor_C == kNoMotorReading_C;  // exact: −1000 / 10 in a double
}

/// A COMM_GET_VALUES_SELECTIVE reply in SI; fields the mask left out are NaN (or 0 for the integers).
struct Values {
  std::uint32_t mask = 0;
  double temp_fet_C = kNaN, temp_motor_C = kNaN;
  double current_motor_A = kNaN, current_in_A = kNaN;  ///< averages since the previous read
  double i_d_A = kNaN, i_q_A = kNaN;                   ///< averages since the previous read
  double duty = kNaN;
  double erpm = kNaN;  ///< electrical revolutions per minute
  double v_in_V = kNaN;
  double amp_hours_Ah = kNaN, amp_hours_charged_Ah = kNaN, watt_hours_Wh = kNaN, watt_hours_charged_Wh = kNaN;
  std::int32_t tachometer = 0, tachometer_abs = 0;
  std::uint8_t fault = 0;
  double pid_pos_deg = kNaN;
  std::uint8_t controller_id = 0;
  std::array<double, 3> temp_mos_C{kNaN, kNaN, kNaN};
  double v_d_V = kNaN, v_q_V = kNaN;  ///< averages since the previous read
  std::uint8_t status_bits = 0;
};

enum class ParseResult { kOk, kNotValues, kShort, kTrailing };

/// Parses a reassembled reply (its first byte the command). kShort: fewer bytes than the mask names;
/// kTrailing: more.
[[nodiscard]] ParseResult parse_values(std::span<const std::uint8_t> payload, Values& out) noexcept;

/// A status broadcast (comm_can.c, comm_can_send_status1…6); `number` 1–6, fields of the others NaN.
struct Status {
  std::uint8_t controller_id = 0;
  int number = 0;
  double erpm = kNaN, current_A = kNaN, duty = kNaN;                                       // 1
  double amp_hours_Ah = kNaN, amp_hours_charged_Ah = kNaN;                                 // 2
  double watt_hours_Wh = kNaN, watt_hours_charged_Wh = kNaN;                               // 3
  double temp_fet_C = kNaN, temp_motor_C = kNaN, current_in_A = kNaN, pid_pos_deg = kNaN;  // 4
  std::int32_t tachometer = 0;                                                             // 5
  double v_in_V = kNaN;                                                                    // 5
  std::array<double, 4> adc_V{kNaN, kNaN, kNaN, kNaN};  ///< 6: ADC1–3 and the PPM input (ppm as given)
};

/// Counters by kind of input (published in diagnostics; numbers only ever grow).
struct VescCounters {
  std::uint64_t frames = 0;
  std::uint64_t replies = 0;          ///< COMM_GET_VALUES_SELECTIVE replies delivered
  std::uint64_t statuses = 0;         ///< status broadcasts delivered
  std::uint64_t foreign = 0;          ///< standard IDs, or addressed to / sent by another node
  std::uint64_t unknown_packet = 0;   ///< a CAN_PACKET_ID this decoder does not read
  std::uint64_t wrong_length = 0;     ///< a frame too short for its packet
  std::uint64_t out_of_order = 0;     ///< a buffer fill at an offset other than the fill level
  std::uint64_t overflow = 0;         ///< a buffer longer than the decoder's
  std::uint64_t length_mismatch = 0;  ///< PROCESS_RX_BUFFER's length is not the fill level
  std::uint64_t crc_error = 0;
  std::uint64_t not_values = 0;   ///< a reply to another command
  std::uint64_t short_reply = 0;  ///< fewer bytes than its mask names
  std::uint64_t trailing = 0;     ///< more bytes than its mask names
  std::uint64_t wrong_mask = 0;   ///< a reply whose mask lacks what was asked for
  std::uint64_t error_frames = 0;
};

/// Reassembles replies addressed to `own_id` from `controller_id` and reads its status broadcasts.
class VescDecoder {
 public:
  enum class Event { kNone, kValues, kStatus };

  /// `required_mask`: bits a reply must carry to be delivered (others are counted as wrong_mask).
  VescDecoder(std::uint8_t controller_id, std::uint8_t own_id, std::uint32_t required_mask = kEstimatorMask) noexcept;

  [[nodiscard]] Event decode(const CanFrame& f) noexcept;
  /// The last reply delivered (valid after kValues).
  [[nodiscard]] const Values& values() const noexcept { return values_; }
  /// The last status delivered (valid after kStatus).
  [[nodiscard]] const Status& status() const noexcept { return status_; }
  [[nodiscard]] const VescCounters& counters() const noexcept { return counters_; }

  /// Bytes the reassembly buffer holds (VESC's own RX_BUFFER_SIZE is larger; replies used here are < 100).
  static constexpr std::size_t kBufferSize = 512;

 private:
  [[nodiscard]] Event fill(const CanFrame& f, std::size_t header) noexcept;
  [[nodiscard]] Event process(std::span<const std::uint8_t> payload) noexcept;
  [[nodiscard]] Event decode_status(const CanFrame& f, Packet p) noexcept;

  std::uint8_t controller_id_, own_id_;
  std::uint32_t required_mask_;
  std::array<std::uint8_t, kBufferSize> buffer_{};
  std::size_t fill_ = 0;
  Values values_;
  Status status_;
  VescCounters counters_;
};

/// A reply as an averaged rotor-frame sample over the window [t_start_ns, t_ns] (the previous reply's
/// and this one's receive times: VESC's averages run from read to read). ω_el = ERPM·2π/60; T_winding is
/// the motor sensor (NaN where the firmware has no reading of it: kNoMotorReading_C), T_drive the FET's. The
/// sample carries no magnet temperature.
[[nodiscard]] core::AveragedSample to_averaged_sample(const Values& v, std::int64_t t_start_ns, std::int64_t t_ns) noexcept;

}  // namespace rpem::can::vesc
