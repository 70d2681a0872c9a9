#pragma once
// What a VESC running its FOC firmware does, control cycle by control cycle, as far as it shapes what
// COMM_GET_VALUES reports (README "Firmware", each behaviour with the file and function of vedderb/bldc it
// follows; re-expressed from reading, no code copied):
//  - the control interrupt (motor/mcpwm_foc.c, mcpwm_foc_adc_int_handler, control_current,
//    update_valpha_vbeta): currents sampled at the PWM, Park at the frame in use, PI current control,
//    the reported v_d, v_q (dead-time compensated, low-passed by a speed-dependent filter in the stationary
//    frame), the undriven branch (i_d = i_q = 0, the measured back EMF tracked into v_d, v_q), the observer,
//    the PLL (its speed is the reported ERPM), the tachometer;
//  - mc_interface_mc_timer_isr (motor/mc_interface.c): single-precision sums of i_d, i_q, v_d, v_q and the
//    motor and input currents every cycle, read and reset by mc_interface_read_reset_avg_*;
//  - the 1 kHz timer thread (mcpwm_foc.c, timer_update): the sensorless open-loop start-up and the switching
//    off of the bridge when the current command is below cc_min_current;
//  - in Hall mode (Firmware::hall), the angle from the Hall sensors (hall.hpp: foc_correct_hall) in both branches of
//    the interrupt, the observer's above foc_sl_erpm.
#include <array>
#include <cstdint>

#include "indep_vesc/case.hpp"
#include "indep_vesc/hall.hpp"
#include "indep_vesc/observer.hpp"

namespace indep::vesc {

/// The firmware's numbers, resolved (the VESC's motor configuration is what its detection measured).
struct FirmwareParams {
  double dt_s = 80e-6;  // control period: 2/f_zv
  double f_zv_Hz = 25000.0;
  double r_Ohm = 0.0, l_H = 0.0, psi_Wb = 0.0;  // foc_motor_r, foc_motor_l, foc_motor_flux_linkage
  double kp = 0.0, ki = 0.0;                    // foc_current_kp, foc_current_ki
  std::array<int, 8> hall_table{kHallInvalid, kHallInvalid, kHallInvalid, kHallInvalid,
                                kHallInvalid, kHallInvalid, kHallInvalid, kHallInvalid};  // foc_hall_table
  Firmware conf;  // the rest of the configuration, as given
};

// hall: the Hall angle alone; hall_blend: blended with the observer's (between foc_sl_erpm_start and foc_sl_erpm).
enum class AngleSource : std::uint8_t { off, observer, startup, openloop, hall, hall_blend };
const char* to_string(AngleSource s);

enum class ControlMode : std::uint8_t { none, current, openloop };

struct IsrInput {
  std::array<double, 3> i_meas_A{};  // the phase currents the ADC sampled, after offset and scale
  double v_bus_meas_V = 0.0;         // the input-voltage ADC
  Vec2 v_terminal_ab_V;              // the phase voltages the ADC measures (used while undriven)
  int hall_state = -1;               // the Hall sensors (utils_read_hall), Hall mode only
};

struct IsrOutput {
  bool modulating = false;  // duties for the next update event; false: outputs off
  std::array<double, 3> duty{0.5, 0.5, 0.5};
  AngleSource source = AngleSource::off;
  double phase_rad = 0.0;           // the frame of this cycle's i_d, i_q, v_d, v_q
  double observer_phase_rad = 0.0;  // the observer's angle this cycle (m_phase_now_observer)
  double hall_weight = 0.0;         // Hall mode: the Hall angle's weight in phase_rad (0: the observer's alone)
  bool hall_interpolating = false;  // Hall mode: the Hall angle interpolated (not the nearest state's)
};

/// COMM_GET_VALUES as the firmware computes it, before the wire's scaling (commands.c,
/// commands_process_packet, case COMM_GET_VALUES), in the reply's order.
struct ValuesReply {
  float temp_mos = 0.0f, temp_motor = 0.0f, current_motor = 0.0f, current_in = 0.0f, id = 0.0f, iq = 0.0f;
  float duty_now = 0.0f, rpm = 0.0f, v_in = 0.0f;
  float amp_hours = 0.0f, amp_hours_charged = 0.0f, watt_hours = 0.0f, watt_hours_charged = 0.0f;
  std::int32_t tachometer = 0, tachometer_abs = 0;
  std::uint8_t fault_code = 0;
  float pid_pos = 0.0f;
  std::uint8_t controller_id = 0;
  float temp_mos_1 = 0.0f, temp_mos_2 = 0.0f, temp_mos_3 = 0.0f;
  float vd = 0.0f, vq = 0.0f;
  std::uint8_t status = 0;
};

/// COMM_GET_VALUES_SETUP's values (commands.c, case COMM_GET_VALUES_SETUP; one VESC).
struct SetupReply {
  float temp_mos = 0.0f, temp_motor = 0.0f, current_tot = 0.0f, current_in_tot = 0.0f, duty_now = 0.0f, rpm = 0.0f;
  float speed = 0.0f, v_in = 0.0f, battery_level = 0.0f, amp_hours = 0.0f, amp_hours_charged = 0.0f;
  float watt_hours = 0.0f, watt_hours_charged = 0.0f, distance = 0.0f, distance_abs = 0.0f, pid_pos = 0.0f;
  std::uint8_t fault_code = 0, controller_id = 0, num_vescs = 1;
  float battery_wh = 0.0f;
};

class VescFirmware {
 public:
  explicit VescFirmware(const FirmwareParams& p);

  // Commands, as apps and VESC Tool give them (mcpwm_foc_set_current, _release_motor, _set_openloop_current,
  // _set_current_off_delay, _stop_pwm).
  void set_current(double i_A);
  void release();
  void set_openloop_current(double i_A, double erpm);
  void set_current_off_delay(double s);
  void stop_pwm();
  /// What the flux measurement writes into the configuration: ψ and the observer gain 0.5e3/ψ².
  void set_flux_linkage(double psi_Wb);
  /// foc_current_kp, foc_current_ki (the flux measurement sets its own for its duration).
  void set_current_gains(double kp, double ki);

  /// One control interrupt.
  IsrOutput isr(const IsrInput& in);
  /// The foc timer thread's 1 ms step (open-loop start-up, bridge off).
  void timer_1ms();
  /// The mc_interface thread's slow inputs: the motor's and the FETs' NTC readings (filtered here).
  void temperatures_1ms(double motor_C, double fet_C);

  /// COMM_GET_VALUES: reads and resets the averages.
  ValuesReply read_values();
  /// COMM_GET_VALUES_SETUP (resets nothing).
  [[nodiscard]] SetupReply read_setup(const SetupSettings& s, int pole_pairs) const;

  [[nodiscard]] bool running() const { return running_; }
  [[nodiscard]] ControlMode mode() const { return mode_; }
  [[nodiscard]] double duty_now() const { return duty_now_; }
  [[nodiscard]] double erpm() const;  // the PLL's speed, as reported (direction applied)
  [[nodiscard]] double pll_speed_rad_s() const { return pll_.speed_rad_s(); }
  /// mcpwm_foc_get_rpm_faster's speed: the angle's differences low-passed with 0.2 per cycle [rad/s].
  [[nodiscard]] double speed_faster_rad_s() const { return speed_est_faster_; }
  [[nodiscard]] bool startup_override() const { return override_; }
  [[nodiscard]] double psi_Wb() const { return psi_; }
  [[nodiscard]] const FirmwareParams& params() const { return p_; }
  [[nodiscard]] const HallAngle& hall() const { return hall_; }
  /// This cycle's values as they enter the sums (mcpwm_foc_get_id/iq/vd/vq, direction not applied).
  [[nodiscard]] Vec2 i_dq_A() const { return {id_, iq_}; }
  [[nodiscard]] Vec2 v_dq_V() const { return {vd_, vq_}; }
  [[nodiscard]] double cycles_since_read() const { return static_cast<double>(iterations_); }

 private:
  void control_current(double phase, Vec2 i_ab, double id_target, double iq_target);
  Vec2 reported_voltage(Vec2 mod_ab_raw, double phase);
  void run_observer(Vec2 v_ab, Vec2 i_ab, double offset_cycles);
  /// Hall mode: foc_correct_hall on this cycle's observer angle; sets out's source and weight.
  double hall_phase(int state, IsrOutput& out);
  [[nodiscard]] double voltage_filter_const() const;
  void speed_and_tachometer(double phase);
  void accumulate(double input_voltage);
  [[nodiscard]] double dir() const { return p_.conf.invert_direction ? -1.0 : 1.0; }

  FirmwareParams p_;
  FluxObserver observer_;
  Pll pll_;
  HallAngle hall_;
  double psi_;
  double observer_gain_;
  double gamma_now_;  // the observer's gain this millisecond (timer_update schedules it on the duty cycle)

  bool running_ = false, released_ = false;
  ControlMode mode_ = ControlMode::none;
  double id_set_ = 0.0, iq_set_ = 0.0, off_delay_s_ = 0.0;
  double openloop_speed_ = 0.0, openloop_angle_ = 0.0;

  double v_bus_ = 0.0, v_in_filtered_ = 0.0;
  double id_ = 0.0, iq_ = 0.0, id_filter_ = 0.0, iq_filter_ = 0.0;
  double vd_ = 0.0, vq_ = 0.0, vd_int_ = 0.0, vq_int_ = 0.0;
  double mod_d_ = 0.0, mod_q_ = 0.0, mod_q_filter_ = 0.0, duty_now_ = 0.0;
  Vec2 mod_measured_ab_, mod_filter_ab_, v_ab_;
  double i_bus_ = 0.0, i_abs_filter_ = 0.0;
  double phase_ = 0.0, phase_observer_ = 0.0, phase_before_ = 0.0, speed_est_fast_ = 0.0, speed_est_faster_ = 0.0;

  // Open-loop start-up (timer_update).
  double hyst_timer_ = 0.0, min_rpm_timer_ = 0.0, phase_override_ = 0.0, override_observer_angle_ = 0.0;
  bool override_ = false;

  std::int32_t tacho_ = 0, tacho_abs_ = 0;
  int tacho_step_last_ = 0;
  double amp_s_ = 0.0, amp_s_charged_ = 0.0, watt_s_ = 0.0, watt_s_charged_ = 0.0;
  double temp_motor_ = 0.0, temp_fet_ = 0.0;
  bool temps_init_ = false;

  // mc_interface's sums: single precision, as the firmware keeps them.
  float sum_id_ = 0.0f, sum_iq_ = 0.0f, sum_vd_ = 0.0f, sum_vq_ = 0.0f, sum_i_motor_ = 0.0f, sum_i_in_ = 0.0f;
  float iterations_ = 0.0f;
};

}  // namespace indep::vesc
