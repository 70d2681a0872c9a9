#pragma once
// COMM_GET_VALUES and COMM_GET_VALUES_SETUP from the firmware's floats to what VESC Tool holds (README "The CSV"):
//  - the firmware writes value·scale, computed in single precision, as an integer (vedderb/bldc util/buffer.c,
//    buffer_append_float32/16): the Cortex-M4's conversion truncates toward zero, saturates, and makes NaN 0;
//    an int16 field keeps the low half of that 32-bit conversion;
//  - VESC Tool divides the integer by the scale in double (vesc_tool vbytearray.cpp, vbPopFrontDouble32/16)
//    into MC_VALUES / SETUP_VALUES (datatypes.h; commands.cpp, case COMM_GET_VALUES / COMM_GET_VALUES_SETUP).
#include <cstdint>

#include "indep_vesc/firmware.hpp"

namespace indep::vesc {

std::int32_t wire_int32(float value, float scale);
std::int16_t wire_int16(float value, float scale);

/// VESC Tool's MC_VALUES (the fields the log writes).
struct McValues {
  double v_in = 0.0, temp_mos = 0.0, temp_mos_1 = 0.0, temp_mos_2 = 0.0, temp_mos_3 = 0.0, temp_motor = 0.0;
  double current_motor = 0.0, current_in = 0.0, id = 0.0, iq = 0.0, rpm = 0.0, duty_now = 0.0;
  double amp_hours = 0.0, amp_hours_charged = 0.0, watt_hours = 0.0, watt_hours_charged = 0.0;
  int tachometer = 0, tachometer_abs = 0;
  double position = 0.0;
  int fault_code = 0, vesc_id = 0;
  double vd = 0.0, vq = 0.0;
};

/// VESC Tool's SETUP_VALUES (the fields the log writes).
struct SetupValues {
  double amp_hours = 0.0, amp_hours_charged = 0.0, watt_hours = 0.0, watt_hours_charged = 0.0;
  double battery_level = 0.0, battery_wh = 0.0, current_in = 0.0, current_motor = 0.0, speed = 0.0;
  double tachometer = 0.0, tachometer_abs = 0.0;
  int num_vescs = 0;
};

McValues decode_values(const ValuesReply& r);
SetupValues decode_setup(const SetupReply& r);

}  // namespace indep::vesc
