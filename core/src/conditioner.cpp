#include "rpem/core/conditioner.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/clock.hpp"

namespace rpem::core {
namespace {

double soft_sign(double x, double band) noexcept {
  if (band <= 0.0) return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
  return std::clamp(x / band, -1.0, 1.0);
}

bool finite(const DriveSample& s) noexcept { return all_finite(s.theta_el_rad, s.omega_el_rad_s, s.u_dc_V, s.u_V, s.i_A); }

}  // namespace

double FluxHarmonic::amplitude_Wb() const noexcept {
  // ψ_h = A·cos x + B·sin x with A = [d_cos, q_cos], B = [d_sin, q_sin]:
  // |ψ_h|² = (|A|² + |B|²)/2 + ((|A|² − |B|²)/2)·cos 2x + (A·B)·sin 2x, whose largest value is below.
  const double aa = d_cos_Wb * d_cos_Wb + q_cos_Wb * q_cos_Wb, bb = d_sin_Wb * d_sin_Wb + q_sin_Wb * q_sin_Wb;
  const double ab = d_cos_Wb * d_sin_Wb + q_cos_Wb * q_sin_Wb;
  return std::sqrt(0.5 * (aa + bb) + std::hypot(0.5 * (aa - bb), ab));
}

SampleConditioner::SampleConditioner(const PerUnitBase& base, const MachinePu& machine,
                                     const ModelExtensions& extensions) noexcept {
  reconfigure(base, machine, extensions);
}

void SampleConditioner::reconfigure(const PerUnitBase& base, const MachinePu& machine, const ModelExtensions& x) noexcept {
  base_ = base;
  machine_ = machine;
  inv_current_A_ = 1.0 / base.current_A;
  inv_voltage_V_ = 1.0 / base.voltage_V;
  inv_omega_rad_s_ = 1.0 / base.omega_el_rad_s;
  current_pu_ = ScaledClarke::of(inv_current_A_);
  voltage_pu_ = ScaledClarke::of(inv_voltage_V_);
  extensions_ = x;
  inv_current_gain_ = (Vec3::Ones() + x.current_gain_error).cwiseInverse();
  inv_r_fe_pu_ = x.iron_loss_r_fe_Ohm > 0.0 ? base_.impedance_Ohm / x.iron_loss_r_fe_Ohm : 0.0;
  offset_rotation_ = Rotation::of(x.theta_offset_rad);
  angle_offset_ = x.theta_offset_rad != 0.0;
  phase_corrections_ = !x.current_offset_A.isZero(0.0) || !x.current_gain_error.isZero(0.0);
  saturation_ = x.saturation();
  deadtime_ = x.deadtime_v_err_V != 0.0 || x.deadtime_t_dead_s != 0.0;
  harmonics_ = x.harmonics();
  for (std::size_t j = 0; j < harmonics_pu_.size(); ++j) {
    const FluxHarmonic& h = x.flux_harmonics[j];
    harmonics_pu_[j] = {base.flux_pu(h.d_cos_Wb), base.flux_pu(h.d_sin_Wb), base.flux_pu(h.q_cos_Wb),
                        base.flux_pu(h.q_sin_Wb)};
  }
  cross_ = x.cross_coupling_H_per_A != 0.0 || x.cross_coupling_H_per_A2 != 0.0;
  half_cross_pu_ = 0.5 * x.cross_coupling_H_per_A * base.current_A * base.current_A / base.flux_Wb;
  cross2_pu_ = x.cross_coupling_H_per_A2 * base.current_A * base.current_A * base.current_A / base.flux_Wb;
  cross_x_q_pu_per_A_ = x.cross_coupling_H_per_A / base.inductance_H;
  cross_x_q_pu_per_A2_ = x.cross_coupling_H_per_A2 / base.inductance_H;
  delay_ = x.delay_s > 0.0;
  corrections_ = deadtime_ || inv_r_fe_pu_ > 0.0;
  emf_ = harmonics_ || cross_;
}

Vec2 SampleConditioner::inductances_pu(const Vec2& i_dq_pu) const noexcept {
  Vec2 x(machine_.x_d_pu, machine_.x_q_pu);
  if (saturation_) {
    const Vec2 i_A = i_dq_pu * base_.current_A;
    x[0] *= extensions_.inductance_d.factor(i_A[0]);
    x[1] = x[1] * extensions_.inductance_q.factor(i_A[1]) + (cross_x_q_pu_per_A_ + cross_x_q_pu_per_A2_ * i_A[0]) * i_A[0];
  }
  return x;
}

Vec2 SampleConditioner::extra_emf_pu(const Rotation& rot, double n_pu, const Vec2& i_dq_pu, bool harmonics) const noexcept {
  Vec2 e = Vec2::Zero();
  if (!emf_) return e;
  if (harmonics && harmonics_) {
    for (std::size_t j = 0; j < harmonics_pu_.size(); ++j) {
      const FluxHarmonic& h = harmonics_pu_[j];
      if (h.nominal()) continue;
      const double order = kFluxHarmonicOrders[j];
      const Rotation z = multiple(rot, kFluxHarmonicOrders[j]);
      const double psi_d = h.d_cos_Wb * z.cos + h.d_sin_Wb * z.sin, psi_q = h.q_cos_Wb * z.cos + h.q_sin_Wb * z.sin;
      const double dpsi_d = order * (h.d_sin_Wb * z.cos - h.d_cos_Wb * z.sin);
      const double dpsi_q = order * (h.q_sin_Wb * z.cos - h.q_cos_Wb * z.sin);
      e += Vec2(dpsi_d - psi_q, dpsi_q + psi_d);  // ∂ψ_h/∂ϑ + J·ψ_h
    }
  }
  if (cross_) e[1] += (half_cross_pu_ + cross2_pu_ * i_dq_pu[0]) * i_dq_pu[1] * i_dq_pu[1];  // J·[Δψ_d, 0]
  return n_pu * e;
}

Vec2 SampleConditioner::delayed_command_alphabeta_pu(double dt_s) const noexcept {
  // The command that acts over this interval was issued delay = (m + f)·dt before it: for the first
  // f of the interval the older one of the two issued around that instant still holds (zero-order hold).
  const double periods = std::clamp(extensions_.delay_s / dt_s, 0.0, kMaxDelayPeriods + 0.999999);
  const int m = static_cast<int>(periods);
  const double f = periods - m;
  return (1.0 - f) * commands_[static_cast<std::size_t>(m)] + f * commands_[static_cast<std::size_t>(m) + 1];
}

Vec3 SampleConditioner::corrected_phases_A(const Vec3& measured_A) const noexcept {
  return (measured_A - extensions_.current_offset_A).cwiseProduct(inv_current_gain_);
}

inline Vec2 SampleConditioner::current_alphabeta_pu(const DriveSample& s, const Rotation& logged) const noexcept {
  if (s.current_frame == Frame::kAbc) return current_pu_(phase_corrections_ ? corrected_phases_A(s.i_A) : Vec3(s.i_A));
  const Vec2 i_ab = s.current_frame == Frame::kAlphaBeta ? Vec2(s.i_A.head<2>()) : inverse_park(s.i_A.head<2>(), logged);
  // A drive that logs αβ or dq made them from its phase measurements; the corrections act there.
  return phase_corrections_ ? current_pu_(corrected_phases_A(inverse_clarke(i_ab))) : Vec2(i_ab * inv_current_A_);
}

inline Vec2 SampleConditioner::command_alphabeta_pu(const DriveSample& s, const Rotation& logged) const noexcept {
  switch (s.voltage_frame) {
    case Frame::kAbc:
      return voltage_pu_(s.u_V);
    case Frame::kAlphaBeta:
      return s.u_V.head<2>() * inv_voltage_V_;
    case Frame::kDq:
      break;
  }
  return inverse_park(s.u_V.head<2>(), logged) * inv_voltage_V_;
}

double SampleConditioner::deadtime_voltage_V(double u_dc_V) const noexcept {
  return extensions_.deadtime_v_err_V + extensions_.deadtime_t_dead_s * extensions_.switching_frequency_Hz * u_dc_V;
}

inline Vec2 SampleConditioner::deadtime_error_alphabeta_V(const Vec2& i_ab_A, double u_dc_V) const noexcept {
  if (!deadtime_) return Vec2::Zero();
  const double v_err = deadtime_voltage_V(u_dc_V);
  if (v_err == 0.0) return Vec2::Zero();
  const Vec3 i_abc = inverse_clarke(i_ab_A);
  Vec3 leg_error;
  for (int x = 0; x < 3; ++x) leg_error[x] = -v_err * soft_sign(i_abc[x], extensions_.deadtime_current_band_A);
  return clarke(leg_error);  // the zero sequence does not reach the machine
}

inline SampleConditioner::Measured SampleConditioner::measure(const DriveSample& s, const Rotation& logged) const noexcept {
  Measured m;
  m.logged = logged;
  m.rot = angle_offset_ ? compose(m.logged, offset_rotation_) : m.logged;
  m.i_ab_pu = current_alphabeta_pu(s, m.logged);
  m.i_dq_pu = park(m.i_ab_pu, m.rot);
  m.n_pu = s.omega_el_rad_s * inv_omega_rad_s_;  // base_.speed_pu(), without the division
  const Vec2 x = inductances_pu(m.i_dq_pu);
  m.x_d_pu = x[0];
  m.x_q_pu = x[1];
  m.i_fe_dq_pu.setZero();
  if (inv_r_fe_pu_ > 0.0) {
    // Iron loss: the induced voltage n·J·ψ drives i_fe = n·J·ψ/r_fe beside the magnetising current.
    const Vec2 psi(m.x_d_pu * m.i_dq_pu[0] + machine_.psi_m_pu, m.x_q_pu * m.i_dq_pu[1]);
    m.i_fe_dq_pu = (m.n_pu * inv_r_fe_pu_) * Vec2(-psi[1], psi[0]);
    m.i_dq_pu -= m.i_fe_dq_pu;
  }
  return m;
}

SteadyStateInputs SampleConditioner::steady_state(const DriveSample& s) const noexcept {
  SteadyStateInputs out;
  const Measured m = measure(s, Rotation::of(s.theta_el_rad));
  Vec2 u_dq_pu = park(command_alphabeta_pu(s, m.logged), m.rot);
  const double v_err_pu = deadtime_voltage_V(s.u_dc_V) * inv_voltage_V_;
  const double i_norm = m.i_ab_pu.norm();
  if (v_err_pu != 0.0 && i_norm > 0.0) {
    // The six-step leg error's fundamental, opposite to the current: amplitude (4/π)·v_err.
    u_dq_pu -= (4.0 / kPi) * v_err_pu * park(m.i_ab_pu, m.rot) / i_norm;
  }
  // Flux harmonics average out over the revolution a steady-state row stands for; cross-saturation stays.
  out.u_pu = u_dq_pu - machine_.r_s_pu * m.i_fe_dq_pu - extra_emf_pu(m.rot, m.n_pu, m.i_dq_pu, false);
  out.i_pu = m.i_dq_pu;
  out.n_pu = m.n_pu;
  out.x_d_pu = m.x_d_pu;
  out.x_q_pu = m.x_q_pu;
  return out;
}

Vec2 SampleConditioner::logged_current_dq_A(const DriveSample& s, const Rotation& logged) noexcept {
  switch (s.current_frame) {
    case Frame::kAbc:
      return park(clarke(s.i_A), logged);
    case Frame::kAlphaBeta:
      return park(s.i_A.head<2>(), logged);
    case Frame::kDq:
      break;
  }
  return s.i_A.head<2>();
}

Vec2 SampleConditioner::observed_current_dq_A(const DriveSample& s, const Rotation& logged,
                                              const Vec2& i_model_pu) const noexcept {
  // Without observation-side extensions the log's dq frame is the model's.
  if (!angle_offset_ && !phase_corrections_ && inv_r_fe_pu_ == 0.0) return i_model_pu * base_.current_A;
  const Rotation rot = angle_offset_ ? compose(logged, offset_rotation_) : logged;
  Vec2 i_pu = i_model_pu;
  if (inv_r_fe_pu_ > 0.0) {
    const Vec2 x = inductances_pu(i_pu);
    const Vec2 psi(x[0] * i_pu[0] + machine_.psi_m_pu, x[1] * i_pu[1]);
    i_pu += (s.omega_el_rad_s * inv_omega_rad_s_ * inv_r_fe_pu_) * Vec2(-psi[1], psi[0]);
  }
  Vec2 i_ab_A = inverse_park(i_pu * base_.current_A, rot);
  if (phase_corrections_) {
    const Vec3 i_abc = inverse_clarke(i_ab_A);
    i_ab_A = clarke(i_abc.cwiseProduct(Vec3::Ones() + extensions_.current_gain_error) + extensions_.current_offset_A);
  }
  return park(i_ab_A, logged);
}

[[gnu::flatten]] EstimatorSample SampleConditioner::condition(const DriveSample& s) noexcept {
  EstimatorSample out;
  if (!finite(s)) {
    has_previous_ = false;
    out.i_meas_pu.setConstant(std::nan(""));
    return out;
  }

  if (!has_previous_ || s.gap_before) logged_rotation_.reset();  // no increment across a gap
  const Measured m = measure(s, logged_rotation_.at(s.theta_el_rad));
  out.i_meas_pu = m.i_dq_pu;
  if (saturation_) {
    out.x_d_pu = m.x_d_pu;
    out.x_q_pu = m.x_q_pu;
  }

  // The corrections the machine's voltage takes over the coming interval, from the current now: the
  // dead-time error, and the resistive drop of the iron-loss current (which the magnetising-current
  // model does not carry).
  const Vec2 command_ab_pu = command_alphabeta_pu(s, m.logged);
  Vec2 correction_ab_pu = Vec2::Zero();
  if (corrections_) {
    correction_ab_pu = deadtime_error_alphabeta_V(m.i_ab_pu * base_.current_A, s.u_dc_V) * inv_voltage_V_;
    if (inv_r_fe_pu_ > 0.0) correction_ab_pu -= inverse_park(m.i_fe_dq_pu, m.rot) * machine_.r_s_pu;
  }
  const Vec2 emf_pu = extra_emf_pu(m.rot, m.n_pu, m.i_dq_pu, true);

  const bool chained = has_previous_ && !s.gap_before;
  if (chained) {
    auto& iv = out.interval;
    iv.dt_s = to_seconds(s.t_ns - previous_t_ns_);
    iv.n_start_pu = previous_n_pu_;
    iv.n_end_pu = m.n_pu;
    const Vec2 command = delay_ && iv.dt_s > 0.0 ? delayed_command_alphabeta_pu(iv.dt_s) : commands_[0];
    // Without the extensions that add to it, the command is what the machine sees (decided in reconfigure).
    const Vec2 u_held_ab_pu = corrections_ ? Vec2(command + previous_correction_ab_pu_) : command;
    iv.u_start_pu = park(u_held_ab_pu, previous_rotation_);
    iv.u_end_pu = park(u_held_ab_pu, m.rot);
    if (emf_) {
      iv.u_start_pu -= previous_emf_pu_;
      iv.u_end_pu -= emf_pu;
    }
  } else {
    out.resync = true;
    // The gap's length (0 for the first sample) lets the estimator keep ε across a short one.
    out.interval.dt_s = has_previous_ ? to_seconds(s.t_ns - previous_t_ns_) : 0.0;
    out.interval.n_start_pu = m.n_pu;
    out.interval.n_end_pu = m.n_pu;
  }

  if (!delay_) {
    commands_[0] = command_ab_pu;
  } else if (chained) {
    for (std::size_t j = commands_.size() - 1; j > 0; --j) commands_[j] = commands_[j - 1];
    commands_[0] = command_ab_pu;
  } else {
    commands_.fill(command_ab_pu);  // what came before the chain is unknown: the first command stands in
  }
  previous_correction_ab_pu_ = correction_ab_pu;
  previous_emf_pu_ = emf_pu;
  previous_rotation_ = m.rot;
  previous_n_pu_ = m.n_pu;
  previous_t_ns_ = s.t_ns;
  has_previous_ = true;
  return out;
}

}  // namespace rpem::core
