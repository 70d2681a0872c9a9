#include "rpem/sim/sensors.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/frames.hpp"

namespace rpem::sim {

Sensors::Sensors(const SensorConfig& config, int pole_pairs, double period_s, std::uint64_t seed)
    : config_(config),
      pole_pairs_(pole_pairs),
      period_s_(period_s),
      normal_(seed),
      hall_(config.hall, period_s),
      angle_history_mech_(static_cast<std::size_t>(std::max(2, config.speed_window + 1)), 0.0) {
  inv_current_lsb_ = config.current_lsb_A > 0.0 ? 1.0 / config.current_lsb_A : 0.0;
  inv_u_dc_lsb_ = config.u_dc_lsb_V > 0.0 ? 1.0 / config.u_dc_lsb_V : 0.0;
  inv_pole_pairs_ = 1.0 / pole_pairs;
  if (config.encoder_counts > 0.0) {
    encoder_step_rad_ = 2.0 * core::kPi / config.encoder_counts;
    inv_encoder_step_ = config.encoder_counts / (2.0 * core::kPi);
  }
}

double Sensors::quantize(double x, double lsb, double inv_lsb) noexcept {
  if (lsb <= 0.0) return x;
  const double steps = x * inv_lsb;  // round half away from zero without a libm call
  return lsb * static_cast<double>(static_cast<long long>(steps + (steps >= 0.0 ? 0.5 : -0.5)));
}

core::Vec3 Sensors::currents(const core::Vec3& i_abc_A) noexcept {
  core::Vec3 out;
  for (int x = 0; x < 3; ++x) {
    double v = i_abc_A[x] * (1.0 + config_.current_gain_error[x]) + config_.current_offset_A[x];
    if (config_.current_noise_A > 0.0) v += config_.current_noise_A * normal_();
    out[x] = quantize(v, config_.current_lsb_A, inv_current_lsb_);
  }
  return out;
}

double Sensors::angle(double theta_el_true_rad) noexcept {
  double mech = theta_el_true_rad * inv_pole_pairs_;
  if (config_.hall.enabled) {
    mech = hall_.angle(theta_el_true_rad) * inv_pole_pairs_;
  } else if (config_.encoder_counts > 0.0) {
    const double counts = mech * inv_encoder_step_;
    const auto truncated = static_cast<double>(static_cast<long long>(counts));
    mech = encoder_step_rad_ * (truncated > counts ? truncated - 1.0 : truncated);  // floor, without a libm call
  }
  if (++head_ == angle_history_mech_.size()) head_ = 0;
  angle_history_mech_[head_] = mech;
  count_ = std::min(count_ + 1, angle_history_mech_.size());
  return core::wrap_angle(mech * pole_pairs_ - config_.theta_offset_rad);
}

double Sensors::speed() const noexcept {
  if (count_ < 2) return 0.0;
  const std::size_t span = count_ - 1;
  const std::size_t n = angle_history_mech_.size();
  const std::size_t oldest_index = head_ >= span ? head_ - span : head_ + n - span;
  const double oldest = angle_history_mech_[oldest_index];
  return pole_pairs_ * (angle_history_mech_[head_] - oldest) / (static_cast<double>(span) * period_s_);
}

double Sensors::dc_link(double u_dc_V) noexcept {
  double v = u_dc_V;
  if (config_.u_dc_noise_V > 0.0) v += config_.u_dc_noise_V * normal_();
  return quantize(v, config_.u_dc_lsb_V, inv_u_dc_lsb_);
}

}  // namespace rpem::sim
