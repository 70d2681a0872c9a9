#include "indep_vesc/firmware.hpp"

#include <algorithm>
#include <cmath>

namespace indep::vesc {

namespace {

constexpr double kRpmToRadS = 2.0 * kPi / 60.0;

/// The firmware's SIGN: −1 below zero, +1 otherwise (zero included).
double sign(double x) { return x < 0.0 ? -1.0 : 1.0; }

/// Linear map of x from [a, b] onto [c, d] (no clamping).
double map(double x, double a, double b, double c, double d) { return (x - a) * (d - c) / (b - a) + c; }

double clamp_abs(double x, double limit) { return std::clamp(x, -limit, limit); }

}  // namespace

const char* to_string(AngleSource s) {
  switch (s) {
    case AngleSource::off:
      return "off";
    case AngleSource::observer:
      return "observer";
    case AngleSource::startup:
      return "startup";
    case AngleSource::openloop:
      return "openloop";
    case AngleSource::hall:
      return "hall";
    case AngleSource::hall_blend:
      return "hall_blend";
  }
  return "?";
}

VescFirmware::VescFirmware(const FirmwareParams& p)
    : p_(p),
      observer_(p.r_Ohm, p.l_H, p.psi_Wb),
      pll_(p.conf.pll_kp, p.conf.pll_ki),
      hall_(HallSettings{p.hall_table, p.conf.hall_interp_erpm, p.conf.sl_erpm_start, p.conf.sl_erpm}),
      psi_(p.psi_Wb),
      observer_gain_(p.conf.observer_gain_factor / (p.psi_Wb * p.psi_Wb)),
      gamma_now_(4.0 * p.conf.observer_gain_slow * observer_gain_) {}

void VescFirmware::set_current(double i_A) {
  mode_ = ControlMode::current;
  iq_set_ = i_A;
  id_set_ = 0.0;
  if (std::fabs(i_A) < p_.conf.cc_min_current_A) return;
  if (!running_) {
    released_ = false;
    running_ = true;
  }
}

void VescFirmware::release() {
  mode_ = ControlMode::current;
  iq_set_ = 0.0;
  id_set_ = 0.0;
  released_ = true;
}

void VescFirmware::set_openloop_current(double i_A, double erpm) {
  mode_ = ControlMode::openloop;
  iq_set_ = clamp_abs(i_A, p_.conf.l_current_max_A);
  openloop_speed_ = erpm * kRpmToRadS;
  if (std::fabs(i_A) < p_.conf.cc_min_current_A) return;
  if (!running_) {
    released_ = false;
    running_ = true;
  }
}

void VescFirmware::set_current_off_delay(double s) { off_delay_s_ = std::max(off_delay_s_, s); }

void VescFirmware::stop_pwm() {
  running_ = false;
  mode_ = ControlMode::none;
  id_set_ = iq_set_ = 0.0;
}

void VescFirmware::set_flux_linkage(double psi_Wb) {
  psi_ = psi_Wb;
  observer_.set_flux_linkage(psi_Wb);
  observer_gain_ = p_.conf.observer_gain_factor / (psi_Wb * psi_Wb);
}

void VescFirmware::set_current_gains(double kp, double ki) {
  p_.kp = kp;
  p_.ki = ki;
}

double VescFirmware::erpm() const { return dir() * pll_.speed_rad_s() / kRpmToRadS; }

IsrOutput VescFirmware::isr(const IsrInput& in) {
  const Firmware& c = p_.conf;
  if (v_bus_ == 0.0) v_bus_ = v_in_filtered_ = in.v_bus_meas_V;  // the filters start from the first reading
  v_bus_ += 0.1 * (in.v_bus_meas_V - v_bus_);
  v_in_filtered_ += 0.02 * (in.v_bus_meas_V - v_in_filtered_);

  IsrOutput out;
  double phase = 0.0;
  if (running_) {
    const Vec2 i_ab = clarke(in.i_meas_A);  // three shunts: the full Clarke transform
    double iq_set = iq_set_;
    // The observer sees last cycle's voltage (update_valpha_vbeta runs later in the cycle) and this cycle's
    // current; its angle is advanced by (0.5 + foc_observer_offset) periods.
    run_observer(v_ab_, i_ab, 0.5 + c.observer_offset);
    phase = phase_observer_;
    out.source = AngleSource::observer;
    if (c.hall) {
      // FOC_SENSOR_MODE_HALL: the Hall angle (the start-up's angle only while the state read is invalid; the
      // observer is not forced and no boost is added in this mode).
      phase = hall_phase(in.hall_state, out);
    } else if (override_) {
      phase = phase_override_;
      observer_.force(override_observer_angle_, i_ab);
      iq_set += c.sl_openloop_boost_q_A * sign(iq_set);
      if (c.sl_openloop_max_q_A > c.cc_min_current_A) iq_set = clamp_abs(iq_set, c.sl_openloop_max_q_A);
      out.source = AngleSource::startup;
    }
    if (mode_ == ControlMode::openloop) {
      openloop_angle_ = wrap_pi(openloop_angle_ + p_.dt_s * openloop_speed_);
      phase = openloop_angle_;
      out.source = AngleSource::openloop;
      out.hall_weight = 0.0;
      out.hall_interpolating = false;
    }
    iq_set = clamp_abs(iq_set, c.l_current_max_A);  // sensorless: i_d = 0; symmetric current limits
    control_current(phase, i_ab, 0.0, iq_set);
    // Space-vector duties of the raw modulation (foc_svm): min-max zero sequence around the half bus.
    const Vec2 v_cmd = (2.0 / 3.0 * v_bus_) * inverse_park({mod_d_, mod_q_}, phase);
    const std::array<double, 3> v_abc = inverse_clarke(v_cmd);
    const double mid = 0.5 * (std::max({v_abc[0], v_abc[1], v_abc[2]}) + std::min({v_abc[0], v_abc[1], v_abc[2]}));
    for (int k = 0; k < 3; ++k) out.duty[k] = std::clamp(0.5 + (v_abc[k] - mid) / v_bus_, 0.0, 1.0);
    out.modulating = true;
  } else {
    // Undriven: no current; the measured phase voltages (the back EMF) feed the filters and the observer.
    id_ = iq_ = id_filter_ = iq_filter_ = 0.0;
    i_bus_ = i_abs_filter_ = 0.0;
    const Vec2 v_meas = c.off_voltage == OffVoltage::measured ? in.v_terminal_ab_V : Vec2{0.0, 0.0};
    const double fc = voltage_filter_const();
    const Vec2 mod_meas = (1.5 / v_bus_) * v_meas;
    mod_filter_ab_ = c.vdq_filter ? mod_filter_ab_ + fc * (mod_meas - mod_filter_ab_) : mod_meas;
    v_ab_ = v_meas;
    run_observer(v_ab_, {0.0, 0.0}, c.observer_offset);
    phase = phase_observer_;
    if (c.hall) phase = hall_phase(in.hall_state, out);  // the undriven branch corrects with the Halls too
    const Vec2 v_dq = park(v_ab_, phase);
    vd_ += 0.2 * (v_dq.x - vd_);
    vq_ += 0.2 * (v_dq.y - vq_);
    vd_int_ = vd_;  // the current controller restarts from the back EMF
    vq_int_ = vq_;
    mod_d_ = vd_ * 1.5 / v_bus_;
    mod_q_ = vq_ * 1.5 / v_bus_;
    mod_q_filter_ = std::clamp(mod_q_filter_ + 0.2 * (mod_q_ - mod_q_filter_), -1.0, 1.0);
    out.source = AngleSource::off;
  }
  out.observer_phase_rad = phase_observer_;
  phase_ = phase;
  duty_now_ = sign(vq_) * std::hypot(mod_d_, mod_q_) * (2.0 / kSqrt3) / c.overmod_factor;
  speed_and_tachometer(phase);
  accumulate(in.v_bus_meas_V);
  out.phase_rad = phase;
  return out;
}

double VescFirmware::voltage_filter_const() const {
  const double abs_erpm = std::fabs(speed_est_fast_) / kRpmToRadS;
  return abs_erpm < 10000.0 ? map(abs_erpm, 0.0, 10000.0, 0.01, 1.0) : 1.0;
}

void VescFirmware::run_observer(Vec2 v_ab, Vec2 i_ab, double offset_cycles) {
  observer_.update(v_ab, i_ab, p_.dt_s, gamma_now_);
  phase_observer_ = wrap_pi(observer_.angle_rad() + pll_.speed_rad_s() * p_.dt_s * offset_cycles);
}

double VescFirmware::hall_phase(int state, IsrOutput& out) {
  const bool valid = state >= 0 && state < 8 && p_.hall_table[static_cast<std::size_t>(state)] <= 200;
  const double phase = hall_.correct(phase_observer_, pll_.speed_rad_s(), state, p_.dt_s, override_, phase_override_);
  out.hall_weight = hall_.weight();
  out.hall_interpolating = valid && !hall_.nearest();
  if (out.hall_weight > 0.0) {
    out.source = !valid ? AngleSource::startup : out.hall_weight < 1.0 ? AngleSource::hall_blend : AngleSource::hall;
  }
  return phase;
}

void VescFirmware::control_current(double phase, Vec2 i_ab, double id_target, double iq_target) {
  const Firmware& c = p_.conf;
  const double dt = p_.dt_s;
  const double cs = std::cos(phase), sn = std::sin(phase);
  id_ = cs * i_ab.x + sn * i_ab.y;
  iq_ = cs * i_ab.y - sn * i_ab.x;
  id_filter_ += c.current_filter_const * (id_ - id_filter_);
  iq_filter_ += c.current_filter_const * (iq_ - iq_filter_);
  const double ed = id_target - id_, eq = iq_target - iq_;
  vd_int_ += ed * p_.ki * dt;
  vq_int_ += eq * p_.ki * dt;
  vd_ = vd_int_ + ed * p_.kp;  // no decoupling (foc_cc_decoupling's default)
  vq_ = vq_int_ + eq * p_.kp;
  const double max_v = c.l_max_duty * v_bus_ * c.overmod_factor / kSqrt3;
  vd_ = clamp_abs(vd_, max_v * c.mag_vd_max);
  vd_int_ = clamp_abs(vd_int_, max_v * c.mag_vd_max);
  const double max_vq = std::sqrt(std::max(0.0, max_v * max_v - vd_ * vd_));
  vq_ = clamp_abs(vq_, max_vq);
  vq_int_ = clamp_abs(vq_int_, max_vq);
  mod_d_ = vd_ * 1.5 / v_bus_;
  mod_q_ = vq_ * 1.5 / v_bus_;
  mod_q_filter_ += 0.2 * (mod_q_ - mod_q_filter_);
  i_bus_ = mod_measured_ab_.dot(i_ab);  // no input-current sensor: last cycle's measured modulation times i
  i_abs_filter_ = std::hypot(id_filter_, iq_filter_);
  const Vec2 v = reported_voltage(inverse_park({mod_d_, mod_q_}, phase), phase);
  vd_ = cs * v.x + sn * v.y;  // what the sums get: the compensated, filtered voltage in this cycle's frame
  vq_ = cs * v.y - sn * v.x;
}

Vec2 VescFirmware::reported_voltage(Vec2 mod_ab_raw, double phase) {
  const Firmware& c = p_.conf;
  // Dead-time compensation from the signs of the filtered phase currents.
  const std::array<double, 3> i_f = inverse_clarke(inverse_park({id_filter_, iq_filter_}, phase));
  const double sa = sign(i_f[0]), sb = sign(i_f[1]), sc = sign(i_f[2]);
  const double k = c.foc_dt_us * 1e-6 * c.f_zv_Hz;
  mod_measured_ab_ = mod_ab_raw - k * Vec2{(2.0 * sa - sb - sc) / 3.0, (sb - sc) / kSqrt3};
  const double fc = voltage_filter_const();
  mod_filter_ab_ = c.vdq_filter ? mod_filter_ab_ + fc * (mod_measured_ab_ - mod_filter_ab_) : mod_measured_ab_;
  v_ab_ = (2.0 / 3.0 * v_bus_) * mod_filter_ab_;
  return v_ab_;
}

void VescFirmware::speed_and_tachometer(double phase) {
  const double dt = p_.dt_s;
  pll_.update(phase, dt);  // FOC_SPEED_SRC_CORRECTED: the PLL follows the angle in use
  const double diff = std::clamp(wrap_pi(phase - phase_before_), -kPi / 3.0, kPi / 3.0);
  speed_est_fast_ += 0.01 * (diff / dt - speed_est_fast_);
  speed_est_faster_ += 0.2 * (diff / dt - speed_est_faster_);
  pll_.clamp_speed(3.0 * std::fabs(speed_est_fast_));
  phase_before_ = phase;
  int step = static_cast<int>(std::floor((wrap_pi(phase) + kPi) / (2.0 * kPi) * 6.0));
  step = std::clamp(step, 0, 5);
  int d = step - tacho_step_last_;
  tacho_step_last_ = step;
  if (d > 3)
    d -= 6;
  else if (d < -2)
    d += 6;
  tacho_ += d;
  tacho_abs_ += std::abs(d);
}

void VescFirmware::accumulate(double input_voltage) {
  const double i_motor = sign(i_bus_) * i_abs_filter_;  // mcpwm_foc_get_tot_current_filtered
  sum_i_motor_ += static_cast<float>(i_motor);
  sum_i_in_ += static_cast<float>(i_bus_);
  sum_id_ += static_cast<float>(id_);
  sum_iq_ += static_cast<float>(iq_);
  sum_vd_ += static_cast<float>(vd_);
  sum_vq_ += static_cast<float>(vq_);
  iterations_ += 1.0f;
  if (std::fabs(i_motor) > 1.0) {
    const double q = i_bus_ * p_.dt_s;
    if (i_bus_ > 0.0) {
      amp_s_ += q;
      watt_s_ += q * input_voltage;
    } else {
      amp_s_charged_ -= q;
      watt_s_charged_ -= q * input_voltage;
    }
  }
}

void VescFirmware::timer_1ms() {
  const Firmware& c = p_.conf;
  const double dt = 1e-3;
  // The bridge goes off when the command is below the minimum current and no off-delay runs.
  off_delay_s_ = std::max(0.0, off_delay_s_ - dt);
  if (running_ && (mode_ == ControlMode::current || mode_ == ControlMode::openloop)) {
    double min_current = c.cc_min_current_A;
    if (min_current < 0.001 && released_) min_current = 0.001;
    if (std::fabs(iq_set_) < min_current && std::fabs(id_set_) < min_current && off_delay_s_ < dt) {
      mode_ = ControlMode::none;
      running_ = false;
      id_set_ = iq_set_ = 0.0;
    }
  }

  // Sensorless open-loop start-up: below the open-loop speed for sl_openloop_hyst, the commanded angle is
  // taken over for lock + ramp + const seconds, starting 60° ahead of the observer's, ramping to the open-loop
  // speed, the current kept in that frame; the observer is held 45° ahead of the commanded angle.
  const double t_lock = c.sl_openloop_time_lock_s, t_ramp = c.sl_openloop_time_ramp_s, t_const = c.sl_openloop_time_s;
  double ol_current = std::fabs(iq_filter_) + c.sl_openloop_boost_q_A;
  if (c.sl_openloop_max_q_A > 0.0) ol_current = std::clamp(ol_current, 0.0, c.sl_openloop_max_q_A);
  const double ol_erpm_max = clamp_abs(
      map(ol_current, 0.0, c.l_current_max_A, c.openloop_erpm_low * c.openloop_erpm, c.openloop_erpm), c.openloop_erpm);
  double ol_erpm = ol_erpm_max;
  const double time_fwd = t_lock + t_ramp + t_const - min_rpm_timer_;
  if (time_fwd < t_lock) {
    ol_erpm = 0.0;
  } else if (time_fwd < t_lock + t_ramp) {
    ol_erpm = map(time_fwd, t_lock, t_lock + t_ramp, 0.0, ol_erpm);
  }
  ol_erpm = clamp_abs(ol_erpm, ol_erpm_max);
  const double step = (duty_now_ > 0.0 ? 1.0 : -1.0) * ol_erpm * kRpmToRadS * dt;
  if (std::fabs(pll_.speed_rad_s()) < ol_erpm_max * kRpmToRadS && hyst_timer_ < c.sl_openloop_hyst_s) {
    hyst_timer_ += dt;
  } else if (hyst_timer_ > 0.0) {
    hyst_timer_ -= dt;
  }
  if (running_ && std::fabs(duty_now_) < 0.001) {
    hyst_timer_ = min_rpm_timer_ = 0.0;
    override_ = false;
  }
  bool started_now = false;
  if (hyst_timer_ >= c.sl_openloop_hyst_s && min_rpm_timer_ <= 0.0001) {
    min_rpm_timer_ = t_lock + t_ramp + t_const;
    started_now = true;
  }
  if (!running_) min_rpm_timer_ = 0.0;
  if (min_rpm_timer_ > 0.0) {
    phase_override_ += step;
    if (started_now) phase_override_ += duty_now_ > 0.0 ? kPi / 3.0 : -kPi / 3.0;
    phase_override_ = wrap_pi(phase_override_);
    override_ = true;
    min_rpm_timer_ -= dt;
    hyst_timer_ = 0.0;
    override_observer_angle_ = phase_override_ + sign(duty_now_) * kPi / 4.0;
  } else {
    phase_override_ = phase_observer_;
    override_ = false;
  }

  // Observer gain scheduled on the duty cycle (gain at 40 V of modulation, at least the slow fraction), ×4.
  const double g = std::max(std::fabs(duty_now_) * v_bus_ / 40.0, c.observer_gain_slow) * observer_gain_;
  gamma_now_ = 4.0 * g;
}

void VescFirmware::temperatures_1ms(double motor_C, double fet_C) {
  // mc_interface.c (update_override_limits): a motor reading that is not finite or outside −200…600 °C goes into
  // the filter as −100 °C.
  if (!std::isfinite(motor_C) || motor_C > 600.0 || motor_C < -200.0) motor_C = -100.0;
  if (!temps_init_) {
    temp_motor_ = motor_C;
    temp_fet_ = fet_C;
    temps_init_ = true;
  }
  temp_fet_ += 0.1 * (fet_C - temp_fet_);
  temp_motor_ += 0.01 * (motor_C - temp_motor_);
}

ValuesReply VescFirmware::read_values() {
  ValuesReply r;
  const float n = iterations_;
  auto mean = [n](float& sum) {
    const float m = sum / n;  // 0/0 is NaN when no cycle ran since the previous read; the wire makes it 0
    sum = 0.0f;
    return m;
  };
  const auto f = [](double x) { return static_cast<float>(x); };
  const float d = f(dir());
  r.temp_mos = f(temp_fet_);
  r.temp_motor = f(temp_motor_);
  r.current_motor = mean(sum_i_motor_);
  r.current_in = mean(sum_i_in_);
  r.id = mean(sum_id_);
  r.iq = d * mean(sum_iq_);
  r.duty_now = f(dir() * duty_now_);
  r.rpm = f(erpm());
  r.v_in = f(v_in_filtered_);
  r.amp_hours = f(amp_s_ / 3600.0);
  r.amp_hours_charged = f(amp_s_charged_ / 3600.0);
  r.watt_hours = f(watt_s_ / 3600.0);
  r.watt_hours_charged = f(watt_s_charged_ / 3600.0);
  r.tachometer = static_cast<std::int32_t>(dir()) * tacho_;
  r.tachometer_abs = tacho_abs_;
  double deg = phase_ * 180.0 / kPi;  // no encoder: the position is the angle in use
  if (deg < 0.0) deg += 360.0;
  r.pid_pos = f(deg);
  r.controller_id = static_cast<std::uint8_t>(p_.conf.controller_id);
  r.vd = mean(sum_vd_);
  r.vq = d * mean(sum_vq_);
  iterations_ = 0.0f;
  return r;
}

SetupReply VescFirmware::read_setup(const SetupSettings& s, int pole_pairs) const {
  SetupReply r;
  const auto f = [](double x) { return static_cast<float>(x); };
  const double motor_poles = 2.0 * pole_pairs;
  r.temp_mos = f(temp_fet_);
  r.temp_motor = f(temp_motor_);
  r.current_tot = f(sign(i_bus_) * i_abs_filter_);
  r.current_in_tot = f(i_bus_);
  r.duty_now = f(dir() * duty_now_);
  r.rpm = f(erpm());
  r.speed = f(erpm() / (motor_poles / 2.0) / 60.0 * s.wheel_diameter_m * kPi / s.gear_ratio);
  r.v_in = f(v_in_filtered_);
  // Li-ion 3.0–4.2 V per cell, the cell count the closest to the link at 3.7 V per cell.
  const double cells = std::max(1.0, std::round(v_in_filtered_ / 3.7));
  const double level = std::clamp((v_in_filtered_ / cells - 3.0) / 1.2, 0.0, 1.0);
  r.battery_level = f(level);
  r.amp_hours = f(amp_s_ / 3600.0);
  r.amp_hours_charged = f(amp_s_charged_ / 3600.0);
  r.watt_hours = f(watt_s_ / 3600.0);
  r.watt_hours_charged = f(watt_s_charged_ / 3600.0);
  const double tacho_scale = s.wheel_diameter_m * kPi / (3.0 * motor_poles * s.gear_ratio);
  r.distance = f(dir() * tacho_ * tacho_scale);
  r.distance_abs = f(tacho_abs_ * tacho_scale);
  r.battery_wh = f(level * s.battery_ah * cells * 3.7);
  r.controller_id = static_cast<std::uint8_t>(p_.conf.controller_id);
  return r;
}

}  // namespace indep::vesc
