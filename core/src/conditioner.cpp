#include "rpem/core/conditioner.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {
namespace {

double soft_sign(double x, double band) noexcept {
  if (band <= 0.0) return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
  return std::clamp(x / band, -1.0, 1.0);
}

bool finite(const DriveSample& s) noexcept {
  return std::isfinite(s.theta_el_rad) && std::isfinite(s.omega_el_rad_s) && std::isfinite(s.u_dc_V) &&
         s.u_V.allFinite() && s.i_A.allFinite();
}

}  // namespace

SampleConditioner::SampleConditioner(const PerUnitBase& base, const InputCorrections& corrections) noexcept
    : base_(base),
      inv_current_A_(1.0 / base.current_A),
      inv_voltage_V_(1.0 / base.voltage_V),
      inv_omega_rad_s_(1.0 / base.omega_el_rad_s) {
  set_corrections(corrections);
}

void SampleConditioner::set_corrections(const InputCorrections& c) noexcept {
  corrections_ = c;
  inv_current_gain_ = (Vec3::Ones() + c.current_gain_error).cwiseInverse();
}

Vec2 SampleConditioner::current_dq_A(const DriveSample& s, const Rotation& rot) const noexcept {
  switch (s.current_frame) {
    case Frame::kAbc: {
      const Vec3 corrected = (s.i_A - corrections_.current_offset_A).cwiseProduct(inv_current_gain_);
      return park(clarke(corrected), rot);
    }
    case Frame::kAlphaBeta:
      return park(s.i_A.head<2>(), rot);
    case Frame::kDq:
      break;
  }
  return s.i_A.head<2>();
}

Vec2 SampleConditioner::command_alphabeta_V(const DriveSample& s, const Rotation& rot) noexcept {
  switch (s.voltage_frame) {
    case Frame::kAbc:
      return clarke(s.u_V);
    case Frame::kAlphaBeta:
      return s.u_V.head<2>();
    case Frame::kDq:
      break;
  }
  return inverse_park(s.u_V.head<2>(), rot);
}

Vec2 SampleConditioner::deadtime_error_alphabeta_V(const Vec2& i_ab_A, double u_dc_V) const noexcept {
  const InputCorrections& c = corrections_;
  const double v_err = c.deadtime_v_err_V + c.deadtime_t_dead_s * c.switching_frequency_Hz * u_dc_V;
  if (v_err == 0.0) return Vec2::Zero();
  const Vec3 i_abc = inverse_clarke(i_ab_A);
  Vec3 leg_error;
  for (int x = 0; x < 3; ++x) leg_error[x] = -v_err * soft_sign(i_abc[x], c.deadtime_current_band_A);
  return clarke(leg_error);  // the zero sequence does not reach the machine
}

EstimatorSample SampleConditioner::condition(const DriveSample& s) noexcept {
  EstimatorSample out;
  if (!finite(s)) {
    has_previous_ = false;
    out.i_meas_pu.setConstant(std::nan(""));
    return out;
  }

  const Rotation rot = Rotation::of(s.theta_el_rad + corrections_.theta_offset_rad);
  const Vec2 i_dq_A = current_dq_A(s, rot);
  const double n_pu = s.omega_el_rad_s * inv_omega_rad_s_;  // base_.speed_pu(), without the division
  out.i_meas_pu = i_dq_A * inv_current_A_;

  // The command issued now, as the machine will see it (dead-time from the current at issue time).
  const Vec2 u_applied_ab_V =
      command_alphabeta_V(s, rot) + deadtime_error_alphabeta_V(inverse_park(i_dq_A, rot), s.u_dc_V);

  if (has_previous_ && !s.gap_before) {
    auto& iv = out.interval;
    iv.dt_s = 1e-9 * static_cast<double>(s.t_ns - previous_t_ns_);
    iv.n_start_pu = previous_n_pu_;
    iv.n_end_pu = n_pu;
    // Delay extension: the first `delay` of the interval still sees the command before.
    const double w = iv.dt_s > 0.0 ? std::clamp(corrections_.delay_s / iv.dt_s, 0.0, 1.0) : 0.0;
    const Vec2 u_held_ab_pu = ((1.0 - w) * previous_u_ab_V_ + w * older_u_ab_V_) * inv_voltage_V_;
    iv.u_start_pu = park(u_held_ab_pu, previous_rotation_);
    iv.u_end_pu = park(u_held_ab_pu, rot);
  } else {
    out.resync = true;
    // The gap's length (0 for the first sample) lets the estimator keep ε across a short one.
    out.interval.dt_s = has_previous_ ? 1e-9 * static_cast<double>(s.t_ns - previous_t_ns_) : 0.0;
    out.interval.n_start_pu = n_pu;
    out.interval.n_end_pu = n_pu;
  }

  older_u_ab_V_ = has_previous_ ? previous_u_ab_V_ : u_applied_ab_V;
  previous_u_ab_V_ = u_applied_ab_V;
  previous_rotation_ = rot;
  previous_n_pu_ = n_pu;
  previous_t_ns_ = s.t_ns;
  has_previous_ = true;
  return out;
}

}  // namespace rpem::core
