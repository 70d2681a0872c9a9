#include "indep_vesc/app.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace indep::vesc {

namespace {

/// mc_interface_set_current: the app's current in the motor's configured direction.
void mc_set_current(VescFirmware& fw, double i_A) { fw.set_current(fw.params().conf.invert_direction ? -i_A : i_A); }

}  // namespace

App::App(std::vector<Segment> segments) : segments_(std::move(segments)) {}

SegmentKind App::kind_now() const { return done_ || !started_ ? SegmentKind::off : segments_[index_].kind; }

double App::external_torque_Nm() const { return done_ || !started_ ? 0.0 : segments_[index_].external_Nm; }

double App::added_friction_Nm() const { return done_ || !started_ ? 0.0 : segments_[index_].friction_Nm; }

double App::added_viscous_Nm_s() const { return done_ || !started_ ? 0.0 : segments_[index_].viscous_Nm_s; }

void App::begin(std::size_t index, double t_s, VescFirmware& fw) {
  index_ = index;
  t_begin_ = t_s;
  const Segment& s = segments_[index];
  spans_.push_back({s, t_s, t_s});
  ramp_from_A_ = command_A_;
  if (s.kind == SegmentKind::brake) brake_sign_ = fw.erpm() > 0.0 ? -1.0 : 1.0;
  if (s.kind == SegmentKind::flux_measurement) {
    flux_phase_ = Flux::lock;
    flux_ms_ = 0;
    flux_erpm_ = 0.0;
    sum_vd_ = sum_vq_ = sum_id_ = sum_iq_ = sum_undriven_ = 0.0;
    undriven_samples_ = 0;
    kp_before_ = fw.params().kp;
    ki_before_ = fw.params().ki;
    constexpr double kTc = 1500e-6;
    fw.set_current_gains(fw.params().l_H / kTc, fw.params().r_Ohm / kTc);
  }
}

void App::step_1ms(double t_s, VescFirmware& fw) {
  if (done_ || segments_.empty()) {
    fw.release();
    return;
  }
  if (!started_) {
    started_ = true;
    begin(0, t_s, fw);
  }
  while (!run_segment(t_s, fw)) {
    spans_.back().t_end_s = t_s;
    if (index_ + 1 >= segments_.size()) {
      done_ = true;
      fw.release();
      return;
    }
    begin(index_ + 1, t_s, fw);
  }
  spans_.back().t_end_s = t_s + 1e-3;
}

void App::finish(double t_s) {
  if (!spans_.empty() && !done_) spans_.back().t_end_s = std::min(spans_.back().t_end_s, t_s);
}

bool App::run_segment(double t_s, VescFirmware& fw) {
  const Segment& s = segments_[index_];
  const double age = t_s - t_begin_;
  if (s.kind == SegmentKind::flux_measurement) return run_flux_measurement(t_s, fw);
  if (age >= s.duration_s) return false;
  switch (s.kind) {
    case SegmentKind::off:
      fw.release();
      command_A_ = 0.0;
      return true;
    case SegmentKind::current: {
      const double cmd =
          s.ramp_s > 0.0 ? ramp_from_A_ + (s.current_A - ramp_from_A_) * std::min(1.0, age / s.ramp_s) : s.current_A;
      mc_set_current(fw, cmd);
      command_A_ = cmd;
      return !(s.until_erpm > 0.0 && std::fabs(fw.erpm()) >= s.until_erpm);
    }
    case SegmentKind::coast:
      mc_set_current(fw, 0.0);  // below cc_min_current: keeps the mode, does not start a stopped bridge
      fw.set_current_off_delay(s.duration_s - age + 2e-3);
      command_A_ = 0.0;
      return true;
    case SegmentKind::brake: {
      const double cmd = brake_sign_ * std::fabs(s.current_A);
      mc_set_current(fw, cmd);
      command_A_ = cmd;
      const double erpm = fw.erpm();
      return !((s.until_erpm > 0.0 && std::fabs(erpm) < s.until_erpm) || erpm * brake_sign_ > 0.0);
    }
    case SegmentKind::flux_measurement:
      break;
  }
  return false;
}

bool App::run_flux_measurement(double t_s, VescFirmware& fw) {
  (void)t_s;
  const Segment& s = segments_[index_];
  const Firmware& c = fw.params().conf;
  const double dir = c.invert_direction ? -1.0 : 1.0;
  const double duty_target = std::min(0.3, 0.9 * c.l_max_duty);
  switch (flux_phase_) {
    case Flux::lock:
      fw.set_openloop_current(flux_ms_ * s.current_A / 200.0, 0.0);
      if (++flux_ms_ >= 200) {
        flux_phase_ = Flux::hold;
        flux_ms_ = 0;
      }
      return true;
    case Flux::hold:  // the locked current stays as the last command left it
      if (++flux_ms_ >= 1000) {
        flux_phase_ = Flux::ramp;
        flux_ms_ = 0;
      }
      return true;
    case Flux::ramp:
      if (std::fabs(fw.duty_now()) >= duty_target || flux_erpm_ >= 12000.0) {
        flux_phase_ = Flux::settle;
        flux_ms_ = 0;
        return true;
      }
      flux_erpm_ += s.erpm_per_s / 1000.0;
      fw.set_openloop_current(s.current_A, dir * flux_erpm_);
      if (++flux_ms_ >= 15000) {  // the firmware gives up (linkage −1) and releases the motor
        fw.stop_pwm();
        fw.set_current(0.0);
        fw.set_current_gains(kp_before_, ki_before_);
        flux_phase_ = Flux::stopped;
        return false;
      }
      return true;
    case Flux::settle:
      if (++flux_ms_ >= 1000) {
        flux_phase_ = Flux::average;
        flux_ms_ = 0;
      }
      return true;
    case Flux::average: {
      const Vec2 v = fw.v_dq_V(), i = fw.i_dq_A();
      sum_vd_ += v.x;
      sum_vq_ += v.y;
      sum_id_ += i.x;
      sum_iq_ += i.y;
      if (++flux_ms_ >= 1000) {
        const double n = flux_ms_;
        const double v_mag = std::hypot(sum_vd_ / n, sum_vq_ / n), i_mag = std::hypot(sum_id_ / n, sum_iq_ / n);
        const double rad_s = flux_erpm_ * 2.0 * kPi / 60.0;
        flux_openloop_ = (v_mag - fw.params().r_Ohm * i_mag) / rad_s - i_mag * fw.params().l_H;
        if (flux_openloop_ > 0.0) fw.set_flux_linkage(flux_openloop_);
        flux_phase_ = Flux::configure;
        flux_ms_ = 0;
      }
      return true;
    }
    case Flux::configure:
      if (++flux_ms_ >= 500) {
        fw.stop_pwm();
        fw.set_current(0.0);
        flux_phase_ = Flux::undriven;
        flux_ms_ = 0;
      }
      return true;
    case Flux::undriven: {
      const double w = fw.speed_faster_rad_s();  // mcpwm_foc_get_rpm_faster
      if (std::fabs(fw.duty_now()) < 0.02 || flux_ms_ >= 200 || w == 0.0) {
        end_flux_measurement(fw);
        return false;
      }
      if (flux_ms_ >= 5) {  // the firmware waits 5 ms for the bridge to settle
        sum_undriven_ += fw.v_dq_V().y / w;
        ++undriven_samples_;
      }
      ++flux_ms_;
      return true;
    }
    case Flux::stopped:
      return false;
  }
  return false;
}

void App::end_flux_measurement(VescFirmware& fw) {
  fw.set_current_gains(kp_before_, ki_before_);
  // detect_apply_all keeps the undriven value when it has more than 60 samples of 0.1 ms (here: 1 ms each).
  const double undriven = undriven_samples_ > 0 ? sum_undriven_ / undriven_samples_ : 0.0;
  const double chosen = undriven_samples_ * 10 > 60 ? undriven : flux_openloop_;
  if (chosen > 0.0) fw.set_flux_linkage(chosen);
  flux_ = chosen;
  flux_phase_ = Flux::stopped;
}

}  // namespace indep::vesc
