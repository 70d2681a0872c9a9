#pragma once
// The physics side of the emulated VESC (`rpem sim --vesc`): the simulated drive stepped one control cycle
// at a time, and what the firmware would read from it. The protocol side — requests, the reply's bytes,
// the buffer protocol, status frames — is can/vesc_firmware.hpp; the CAN I/O is the tool's.
//
// Averages as the firmware keeps them (vedderb/bldc motor/mc_interface.c): mc_interface_mc_timer_isr adds
// mcpwm_foc_get_id/iq/vd/vq to sums and counts the iterations once per control cycle;
// mc_interface_read_reset_avg_id/iq/vd/vq (and _motor_current, _input_current) divide and zero them. So
// a read returns the means over every cycle since the previous read — whoever read it — and a read
// with no cycle since the previous one is 0/0 (NaN; the reply carries 0, can/vesc_firmware.hpp).
// The cycles are sim/cycle_average.hpp's (measured current at the cycle's start, mean rotor-frame voltage)
// in the controller's frame — the commanded angle in open loop (sim/regime.hpp), whose speed the firmware's
// PLL then reports (run here as the firmware runs it, once per cycle: its speed lags a ramp by k_p/k_i,
// docs/derivations.md §13, "Speed at the read"). With the bridge off the firmware sums what mcpwm_foc_adc_int_handler leaves when "Motor
// is not running" (vedderb/bldc motor/mcpwm_foc.c, since b1945b7d of 2020 in this form): i_d = i_q = 0, and
// v_d, v_q the Park transform at the observer's angle of the phase voltages it measures — the back EMF —
// through UTILS_LP_FAST with 0.2 per cycle, starting from the last modulated v_d, v_q (docs/can-vesc.md,
// "Regimes").

#include <cstdint>

#include "rpem/can/vesc.hpp"
#include "rpem/sim/cycle_average.hpp"
#include "rpem/sim/drive_simulator.hpp"

namespace rpem::sim {

class VescMotor {
 public:
  struct Settings {
    std::uint8_t controller_id = 0;
    double temp_fet_C = 40.0;  ///< the power stage's temperature (the scenario does not model it)
  };

  VescMotor(Scenario scenario, Settings settings);

  /// Runs control cycles until the simulated time (0 at the first cycle) reaches `t_ns`. False once the
  /// scenario has ended.
  bool advance_to(std::int64_t t_ns) noexcept;
  /// Runs one control cycle. False once the scenario has ended.
  bool step() noexcept;
  [[nodiscard]] std::int64_t time_ns() const noexcept { return row_.sample.t_ns; }
  /// Control cycles since the previous read.
  [[nodiscard]] int cycles_since_read() const noexcept { return sums_.cycles(); }
  /// The last complete control cycle (valid after the second step).
  [[nodiscard]] const ControlCycle& last_cycle() const noexcept { return last_cycle_; }
  [[nodiscard]] const DriveSimulator& simulator() const noexcept { return simulator_; }
  /// The true state at the last cycle's start.
  [[nodiscard]] const TruthRow& truth() const noexcept { return truth_; }

  /// What COMM_GET_VALUES_SELECTIVE reads now, every field filled: the averages since the previous read
  /// (then reset) and the instantaneous filtered values.
  [[nodiscard]] can::vesc::Values read_values() noexcept;
  /// Status broadcast `number` (1–6): instantaneous values only; reads no average.
  [[nodiscard]] can::vesc::Status status(int number) const noexcept;

 private:
  void account(const ControlCycle& c) noexcept;
  /// The cycle as the firmware sums it, given the true state at its start.
  [[nodiscard]] ControlCycle firmware_view(ControlCycle c, const TruthRow& at_start) noexcept;

  DriveSimulator simulator_;
  Settings settings_;
  CycleExtractor cycles_;
  CycleAccumulator sums_;
  io::DriveLogRow row_;
  TruthRow truth_;
  ControlCycle last_cycle_;
  core::Vec2 v_dq_filter_V_ = core::Vec2::Zero();  ///< state_now->vd, vq (low-passed while undriven)
  /// The firmware's PLL on the angle in use, once per cycle (motor/foc_math.c, foc_pll_run, the default gains
  /// can::vesc::kDefaultPllKp/Ki): its speed is the ERPM the firmware reports (mcpwm_foc_get_rpm).
  double pll_angle_rad_ = 0.0;
  double pll_speed_rad_s_ = 0.0;
  int pll_cycles_ = 0;
  bool started_ = false;
  double input_current_sum_A_ = 0.0;  ///< m_input_current_sum: power-balance input current per cycle
  std::int64_t tacho_steps_ = 0;      ///< 6 per electrical revolution (mc_interface_get_tachometer_value)
  std::int64_t tacho_abs_steps_ = 0;
  int tacho_sector_ = 0;  ///< m_tacho_step_last: the sector of the last cycle's angle in use
  bool has_sector_ = false;
  double amp_hours_ = 0.0, amp_hours_charged_ = 0.0, watt_hours_ = 0.0, watt_hours_charged_ = 0.0;
  double last_input_current_A_ = 0.0;
};

}  // namespace rpem::sim
