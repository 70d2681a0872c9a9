#include "rpem/sim/vesc_motor.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/clock.hpp"
#include "rpem/core/units.hpp"

#include "rpem/core/frames.hpp"

namespace rpem::sim {
namespace {

/// Input current from the power balance of a cycle (amplitude-invariant frame: P = 3/2·u·i).
double input_current_A(const ControlCycle& c) noexcept {
  return c.u_dc_V > 0.0 ? 1.5 * c.u_dq_V.dot(c.i_dq_A) / c.u_dc_V : 0.0;
}

}  // namespace

VescMotor::VescMotor(Scenario scenario, Settings settings) : simulator_(std::move(scenario)), settings_(settings) {}

bool VescMotor::step() noexcept {
  const TruthRow at_start = truth_;  // the start of the cycle the next row completes
  const std::int64_t before_ns = row_.sample.t_ns;
  if (!simulator_.next(row_, truth_)) return false;
  const double dt_s = started_ ? core::to_seconds(row_.sample.t_ns - before_ns) : 0.0;
  if (pll_cycles_++ < 2) {
    // The drive is running when the emulation begins: the PLL is locked on the rotor, its angle one cycle
    // ahead (after each update θ̂ predicts the next cycle's angle; e = 0 at a constant speed).
    pll_speed_rad_s_ = truth_.omega_el_rad_s;
    pll_angle_rad_ = core::wrap_angle(row_.sample.theta_el_rad + pll_speed_rad_s_ * dt_s);
  } else {
    // foc_pll_run: e = wrap(θ − θ̂), θ̂ += (ω̂ + k_p·e)·dt, ω̂ += k_i·e·dt.
    const double e = core::wrap_angle(row_.sample.theta_el_rad - pll_angle_rad_);
    pll_angle_rad_ = core::wrap_angle(pll_angle_rad_ + (pll_speed_rad_s_ + can::vesc::kDefaultPllKp * e) * dt_s);
    pll_speed_rad_s_ += can::vesc::kDefaultPllKi * e * dt_s;
  }
  started_ = true;
  if (const auto c = cycles_.add(row_)) account(firmware_view(*c, at_start));
  return true;
}

ControlCycle VescMotor::firmware_view(ControlCycle c, const TruthRow& at_start) noexcept {
  if (at_start.modulating()) {
    v_dq_filter_V_ = c.u_dq_V;
    return c;
  }
  c.i_dq_A.setZero();  // "The current is 0 when the motor is undriven"
  if (at_start.off_report == OffVoltageReport::kZero) {
    v_dq_filter_V_.setZero();
  } else {
    // No current: the terminal voltage is the back EMF, (0, ω·ψm) in the rotor frame; the firmware Parks it
    // at its observer's angle (the measured one here) and low-passes it (UTILS_LP_FAST, 0.2).
    const core::Vec2 e(0.0, at_start.omega_el_rad_s * at_start.parameters.psi_m_Wb);
    const core::Vec2 sensed = core::park(e, core::Rotation::of(core::wrap_angle(c.theta_el_rad - at_start.theta_el_rad)));
    v_dq_filter_V_ += 0.2 * (sensed - v_dq_filter_V_);
  }
  c.u_dq_V = v_dq_filter_V_;
  return c;
}

bool VescMotor::advance_to(std::int64_t t_ns) noexcept {
  while (!started_ || row_.sample.t_ns < t_ns) {
    if (!step()) return false;
  }
  return true;
}

void VescMotor::account(const ControlCycle& c) noexcept {
  last_cycle_ = c;
  sums_.add(c);
  const double dt_s = core::to_seconds(c.end_ns - c.t_ns);
  const double i_in = input_current_A(c);
  last_input_current_A_ = i_in;
  input_current_sum_A_ += i_in;
  // The tachometer counts the 60° sectors the angle in use crosses, once per cycle (mcpwm_foc.c, "Update
  // tachometer"): sector ⌊(θ + π)/(2π)·6⌋ of the wrapped angle, the change taken in (−3, 3].
  const int sector = std::clamp(
      static_cast<int>(std::floor((core::wrap_angle(c.theta_el_rad) + core::kPi) / (2.0 * core::kPi) * 6.0)), 0, 5);
  if (!has_sector_) tacho_sector_ = sector;
  has_sector_ = true;
  int steps = sector - tacho_sector_;
  tacho_sector_ = sector;
  if (steps > 3) steps -= 6;
  if (steps < -2) steps += 6;
  tacho_steps_ += steps;
  tacho_abs_steps_ += std::abs(steps);
  const double ah = std::abs(i_in) * dt_s / 3600.0;
  (i_in >= 0.0 ? amp_hours_ : amp_hours_charged_) += ah;
  (i_in >= 0.0 ? watt_hours_ : watt_hours_charged_) += ah * c.u_dc_V;
}

can::vesc::Values VescMotor::read_values() noexcept {
  can::vesc::Values v;
  const int n = sums_.cycles();
  const double inv = n > 0 ? 1.0 / n : std::nan("");  // 0/0 as mc_interface_read_reset_avg_* divides
  const core::AveragedSample mean = sums_.read_reset();
  v.mask = (std::uint32_t{1} << can::vesc::kFieldCount) - 1;
  v.i_d_A = mean.i_dq_A[0];
  v.i_q_A = mean.i_dq_A[1];
  v.v_d_V = mean.u_dq_V[0];
  v.v_q_V = mean.u_dq_V[1];
  v.current_motor_A = mean.i_dq_A[1];
  v.current_in_A = input_current_sum_A_ * inv;
  input_current_sum_A_ = 0.0;

  // The instantaneous (filtered) values are the status broadcasts' (status() fills them all).
  const can::vesc::Status now = status(0);
  v.temp_fet_C = now.temp_fet_C;
  v.temp_mos_C = {now.temp_fet_C, now.temp_fet_C, now.temp_fet_C};
  v.temp_motor_C = now.temp_motor_C;
  v.duty = now.duty;
  v.erpm = now.erpm;
  v.v_in_V = now.v_in_V;
  v.amp_hours_Ah = now.amp_hours_Ah;
  v.amp_hours_charged_Ah = now.amp_hours_charged_Ah;
  v.watt_hours_Wh = now.watt_hours_Wh;
  v.watt_hours_charged_Wh = now.watt_hours_charged_Wh;
  v.tachometer = now.tachometer;
  v.tachometer_abs = static_cast<std::int32_t>(tacho_abs_steps_);
  v.fault = 0;
  v.pid_pos_deg = now.pid_pos_deg;
  v.controller_id = settings_.controller_id;
  v.status_bits = 0;
  return v;
}

can::vesc::Status VescMotor::status(int number) const noexcept {
  can::vesc::Status s;
  s.controller_id = settings_.controller_id;
  s.number = number;
  const ControlCycle& c = last_cycle_;
  const double u_max = c.u_dc_V / std::sqrt(3.0);
  s.erpm = core::rad_s_to_rpm(pll_speed_rad_s_);  // mc_interface_get_rpm: the PLL's speed
  s.current_A = c.i_dq_A[1];
  s.duty = u_max > 0.0 ? std::copysign(c.u_dq_V.norm() / u_max, c.u_dq_V[1]) : 0.0;
  s.amp_hours_Ah = amp_hours_;
  s.amp_hours_charged_Ah = amp_hours_charged_;
  s.watt_hours_Wh = watt_hours_;
  s.watt_hours_charged_Wh = watt_hours_charged_;
  s.temp_fet_C = settings_.temp_fet_C;
  s.temp_motor_C = std::isnan(row_.sample.t_winding_C) ? settings_.temp_fet_C : row_.sample.t_winding_C;
  s.current_in_A = last_input_current_A_;
  s.pid_pos_deg = std::remainder(row_.sample.theta_el_rad, 2.0 * core::kPi) * 180.0 / core::kPi;
  s.tachometer = static_cast<std::int32_t>(tacho_steps_);
  s.v_in_V = row_.sample.u_dc_V;
  s.adc_V = {0.0, 0.0, 0.0, 0.0};
  return s;
}

}  // namespace rpem::sim
