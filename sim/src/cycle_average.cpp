#include "rpem/sim/cycle_average.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/frames.hpp"

namespace rpem::sim {
namespace {

core::Vec2 stator_frame(core::Frame frame, const core::Vec3& v, const core::Rotation& rot) noexcept {
  switch (frame) {
    case core::Frame::kAbc:
      return core::clarke(v);
    case core::Frame::kAlphaBeta:
      return v.head<2>();
    case core::Frame::kDq:
      break;
  }
  return core::inverse_park(v.head<2>(), rot);
}

}  // namespace

std::optional<ControlCycle> CycleExtractor::add(const io::DriveLogRow& row) noexcept {
  std::optional<ControlCycle> out;
  if (previous_ && !row.sample.gap_before) {
    const core::DriveSample& a = previous_->sample;
    const core::Rotation at = core::Rotation::of(a.theta_el_rad);
    const double step = core::wrap_angle(row.sample.theta_el_rad - a.theta_el_rad);
    const double half = 0.5 * step;
    const double sinc = std::abs(half) < 1e-8 ? 1.0 : std::sin(half) / half;
    ControlCycle c;
    c.t_ns = a.t_ns;
    c.end_ns = row.sample.t_ns;
    c.i_dq_A = core::park(stator_frame(a.current_frame, a.i_A, at), at);
    c.u_dq_V = sinc * core::park(stator_frame(a.voltage_frame, a.u_V, at), core::Rotation::of(a.theta_el_rad + half));
    c.omega_el_rad_s = a.omega_el_rad_s;
    c.theta_el_rad = a.theta_el_rad;
    c.u_dc_V = a.u_dc_V;
    c.t_winding_C = previous_->sample.t_winding_C;
    c.t_magnet_C = previous_->t_magnet_C.value_or(std::nan(""));
    c.t_coolant_C = previous_->sample.t_coolant_C;
    out = c;
  }
  previous_ = row;
  return out;
}

void CycleAccumulator::add(const ControlCycle& c) noexcept {
  if (n_ == 0) first_ns_ = c.t_ns;
  last_end_ns_ = c.end_ns;
  ++n_;
  i_ += c.i_dq_A;
  u_ += c.u_dq_V;
  omega_ += c.omega_el_rad_s;
  u_dc_ += c.u_dc_V;
  t_winding_.add(c.t_winding_C);
  t_magnet_.add(c.t_magnet_C);
  t_coolant_.add(c.t_coolant_C);
}

core::AveragedSample CycleAccumulator::read_reset() noexcept {
  core::AveragedSample s;
  const double inv = n_ > 0 ? 1.0 / n_ : std::nan("");
  s.t_start_ns = first_ns_;
  s.t_ns = last_end_ns_;
  s.i_dq_A = i_ * inv;
  s.u_dq_V = u_ * inv;
  s.omega_el_rad_s = omega_ * inv;
  s.u_dc_V = u_dc_ * inv;
  s.t_winding_C = t_winding_.mean();
  s.t_magnet_C = t_magnet_.mean();
  s.t_coolant_C = t_coolant_.mean();
  *this = CycleAccumulator{};
  return s;
}

WindowAverager::WindowAverager(double rate_Hz, double jitter, std::uint64_t seed)
    : rate_Hz_(rate_Hz), jitter_(jitter), rng_(seed) {}

std::int64_t WindowAverager::draw_length_ns() {
  std::uniform_real_distribution<double> u(1.0 - jitter_, 1.0 + jitter_);
  return std::llround(std::clamp(u(rng_) / rate_Hz_, 0.5e-3, 20e-3) * 1e9);
}

std::optional<core::AveragedSample> WindowAverager::add(const ControlCycle& c) {
  if (!started_) {
    window_end_ns_ = c.t_ns + draw_length_ns();
    started_ = true;
  }
  sums_.add(c);
  if (c.end_ns < window_end_ns_) return std::nullopt;
  window_end_ns_ += draw_length_ns();
  window_end_ns_ = std::max(window_end_ns_, c.end_ns + 1);
  return sums_.read_reset();
}

}  // namespace rpem::sim
