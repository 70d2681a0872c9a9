#include "rpem/core/thermal_held_reading.hpp"

namespace rpem::core {

void HeldReadingCheck::advance(const ThermalFilter& f) noexcept {
  if (!running_) return;
  f.advance_open_loop(t_C_, d_W_);
  f.advance_open_loop(target_t_C_, target_d_W_);
}

ReadingMotion HeldReadingCheck::check(const ThermalFilter& f, const ThermalObservation& o) noexcept {
  if (!running_ || !same_reading(o.value, value_)) {  // a new value: the copy starts here
    running_ = true;
    frozen_ = false;
    value_ = o.value;
    t_at_change_C_ = t_C_ = target_t_C_ = f.temperature_C();
    d_at_change_W_ = d_W_ = target_d_W_ = f.disturbance_W();
    return ReadingMotion::kMoved;
  }
  if (frozen_) return ReadingMotion::kFrozen;
  const double change = o.h.dot(t_C_ - t_at_change_C_) + o.h_d.dot(d_W_ - d_at_change_W_);  // Δ of eq. 14.28
  const double gate = f.config().gate_sigma;
  if (!(change * change > gate * gate * f.innovation_variance(o))) return ReadingMotion::kSame;
  frozen_ = true;
  return ReadingMotion::kFrozenNow;
}

}  // namespace rpem::core
