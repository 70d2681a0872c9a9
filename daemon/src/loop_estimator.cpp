#include "rpem/daemon/loop_estimator.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <type_traits>
#include <variant>

#include "rpem/core/assert.hpp"
#include "rpem/core/clock.hpp"

namespace rpem::daemon {
namespace {

/// std::visit without its std::bad_variant_access: the estimator variant is never valueless (built in
/// place, never assigned), so the calls below are noexcept in fact, not only by their declaration.
template <typename Variant, typename F>
decltype(auto) visit_estimator(Variant& estimators, F&& f) noexcept {
  static_assert(std::variant_size_v<std::remove_const_t<Variant>> == 2);
  RPEM_ASSERT(!estimators.valueless_by_exception(), "the loop's estimator variant always holds one");
  if (auto* e = std::get_if<0>(&estimators)) return f(*e);
  return f(*std::get_if<1>(&estimators));
}

}  // namespace

LoopEstimator::Estimators LoopEstimator::make(SampleKind kind, const core::MachineSi& machine,
                                              const core::EstimatorSettings& settings) noexcept {
  if (kind == SampleKind::kAveraged) return Estimators(std::in_place_index<1>, machine, settings);
  return Estimators(std::in_place_index<0>, machine, settings);
}

LoopEstimator::LoopEstimator(SampleKind kind, const core::MachineSi& machine,
                             const core::EstimatorSettings& settings) noexcept
    : estimator_(make(kind, machine, settings)),
      nominal_period_s_(settings.nominal_sample_period_s),
      max_interval_s_(settings.averaged.max_interval_s) {}

bool LoopEstimator::step(const SourceSample& sample, core::Estimate& estimate, double& dt_s,
                         SampleSummary& summary) noexcept {
  if (sample.index() != estimator_.index()) return false;
  if (auto* phase = std::get_if<core::DriveEstimator>(&estimator_)) {
    const core::DriveSample& s = *std::get_if<core::DriveSample>(&sample);
    estimate = phase->step(s);
    dt_s = nominal_period_s_;
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();  // a phase sample carries no drive sensor
    summary = {s.t_ns, s.rx_ns, s.theta_el_rad, s.omega_el_rad_s, s.u_dc_V, s.t_winding_C, kNaN, s.t_coolant_C};
    return true;
  }
  const core::AveragedSample& a = *std::get_if<core::AveragedSample>(&sample);
  core::AveragedDriveEstimator& averaged = *std::get_if<core::AveragedDriveEstimator>(&estimator_);
  // The time this sample stands for: from the previous window's end — all of it for a window (however
  // long: a window after a gap adapts nothing and is credited nothing); an instantaneous sample stands for
  // at most the interval across which it continues a chain.
  const std::optional<std::int64_t> previous_t_ns = averaged.previous_t_ns();
  estimate = averaged.step(a);
  const double interval_s = previous_t_ns ? core::to_seconds(a.t_ns - *previous_t_ns) : 0.0;
  dt_s = a.t_start_ns < a.t_ns ? std::max(interval_s, 0.0) : std::clamp(interval_s, 0.0, max_interval_s_);
  summary = {a.t_ns,      a.t_ns,       std::numeric_limits<double>::quiet_NaN(), a.omega_el_rad_s, a.u_dc_V, a.t_winding_C,
             a.t_drive_C, a.t_coolant_C};
  return true;
}

void LoopEstimator::reset() noexcept {
  visit_estimator(estimator_, [](core::SampleEstimator auto& e) { e.reset(); });
}
bool LoopEstimator::resynchronize() noexcept {
  return visit_estimator(estimator_, [](core::SampleEstimator auto& e) { return e.resynchronize(); });
}
void LoopEstimator::set_frozen(bool frozen) noexcept {
  visit_estimator(estimator_, [frozen](core::SampleEstimator auto& e) { e.set_frozen(frozen); });
}
void LoopEstimator::set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept {
  visit_estimator(estimator_, [=](core::SampleEstimator auto& e) { e.set_estimates(psi_m_Wb, r_s_Ohm); });
}
void LoopEstimator::reconfigure(const core::MachineSi& machine, const core::EstimatorSettings& settings) noexcept {
  visit_estimator(estimator_, [&](core::SampleEstimator auto& e) { e.reconfigure(machine, settings); });
  nominal_period_s_ = settings.nominal_sample_period_s;
  max_interval_s_ = settings.averaged.max_interval_s;
}
double LoopEstimator::psi_m_Wb() const noexcept {
  return visit_estimator(estimator_, [](const core::SampleEstimator auto& e) { return e.psi_m_Wb(); });
}
double LoopEstimator::r_s_Ohm() const noexcept {
  return visit_estimator(estimator_, [](const core::SampleEstimator auto& e) { return e.r_s_Ohm(); });
}
const core::RpemEstimator& LoopEstimator::core() const noexcept {
  return visit_estimator(estimator_,
                         [](const core::SampleEstimator auto& e) -> const core::RpemEstimator& { return e.core(); });
}

}  // namespace rpem::daemon
