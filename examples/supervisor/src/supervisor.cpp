#include "rpem/supervisor/supervisor.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::supervisor {
namespace {

/// A fused temperature, if the filter gives one (observed or predicted) and it is a number.
std::optional<TemperatureEstimate> fused(double t_C, double sd_K, std::int8_t source) noexcept {
  if (source == rpem::estimate_t::SOURCE_NONE) return std::nullopt;
  if (!std::isfinite(t_C) || !std::isfinite(sd_K) || sd_K < 0.0) return std::nullopt;
  return TemperatureEstimate{t_C, sd_K, 0.0};
}

/// A raw RPEM-derived temperature while rpemd calls it valid (identified, held no longer than
/// validity.max_hold_s) and converged (still within the band over its window: a value still moving towards the
/// part's temperature is not yet one); its σ configured, its age rpemd's.
std::optional<TemperatureEstimate> raw(double t_C, bool valid, bool converged, double age_s,
                                       const PartLimits& part) noexcept {
  if (!valid || !converged || !std::isfinite(t_C) || !std::isfinite(age_s)) return std::nullopt;
  return TemperatureEstimate{t_C, part.raw_sd_K, std::max(age_s, 0.0)};
}

}  // namespace

PartReadings readings_of(const rpem::estimate_t& m, const Config& config) noexcept {
  if (m.thermal_active) {
    return {fused(m.t_magnet_fused_C, m.t_magnet_fused_sd_C, m.t_magnet_source),
            fused(m.t_winding_fused_C, m.t_winding_fused_sd_C, m.t_winding_source)};
  }
  return {raw(m.t_magnet_C, m.psi_m_valid, m.psi_m_converged, m.psi_m_age_s, config.magnet),
          raw(m.t_winding_C, m.r_s_valid, m.r_s_converged, m.r_s_age_s, config.winding)};
}

Received Supervisor::on_message(std::string_view channel, std::span<const std::uint8_t> encoded,
                                std::int64_t now_unix_us) noexcept {
  rpem::estimate_t m{};
  const Admission a = gate_.admit(channel, encoded, now_unix_us, m);
  if (a == Admission::kAccepted) last_ = Accepted{m.utime, readings_of(m, config_)};
  return Received{a, decoded(a) ? std::optional<std::int64_t>(m.utime) : std::nullopt};
}

CurrentLimit Supervisor::current_limit(std::int64_t now_unix_us) const noexcept {
  CurrentLimit out;
  const std::int64_t age_us = last_ ? now_unix_us - last_->utime_us : 0;
  out.fresh = last_ && !config_.freshness.stale(age_us);
  const double message_age_s = 1e-6 * static_cast<double>(std::max<std::int64_t>(age_us, 0));
  const auto upper = [&](const std::optional<TemperatureEstimate>& t, const PartLimits& part) -> std::optional<double> {
    if (!out.fresh || !t) return std::nullopt;
    TemperatureEstimate now = *t;
    now.unrenewed_s += message_age_s;
    return upper_bound_C(part, now);
  };
  if (last_) {
    out.magnet_upper_C = upper(last_->readings.magnet, config_.magnet);
    out.winding_upper_C = upper(last_->readings.winding, config_.winding);
  }
  out.magnet_A = part_current_A(config_.magnet, config_.rated_current_A, out.magnet_upper_C);
  out.winding_A = part_current_A(config_.winding, config_.rated_current_A, out.winding_upper_C);
  out.current_A = std::min(out.magnet_A, out.winding_A);
  return out;
}

}  // namespace rpem::supervisor
