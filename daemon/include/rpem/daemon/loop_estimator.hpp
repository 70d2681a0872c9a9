#pragma once
// The estimator the loop owns, for the kind of sample its source produces: DriveEstimator stepping phase
// samples (the predictor runs at the drive's period), or AveragedDriveEstimator stepping averaged
// rotor-frame samples at their own, uneven host timestamps (docs/derivations.md §11; docs/rpemd.md,
// "Averaged sources"). One interface for the loop's commands and reports; each estimator it may hold is a
// core::SampleEstimator, and their samples are a SourceSample's alternatives, in the same order. Real-time safe.

#include <concepts>
#include <cstdint>
#include <variant>

#include "rpem/core/sample_estimator.hpp"
#include "rpem/daemon/source_sample.hpp"

namespace rpem::daemon {

/// What the loop reports of the newest stepped sample, whatever its kind.
struct SampleSummary {
  std::int64_t t_ns = 0;      ///< drive time (phase) or the window's end (averaged, host time)
  std::int64_t rx_ns = 0;     ///< kernel receive time (CLOCK_REALTIME); 0: unknown
  double theta_el_rad = 0.0;  ///< NaN for averaged samples (they carry no angle)
  double omega_el_rad_s = 0.0;
  double u_dc_V = 0.0;
  double t_winding_sensor_C = 0.0;  ///< a drive's own sensors (NaN: not reported)
  double t_drive_sensor_C = 0.0;
  double t_coolant_sensor_C = 0.0;
};

/// One of the estimators `E`, each a core::SampleEstimator, the k-th stepping a SourceSample's k-th
/// alternative.
template <core::SampleEstimator... E>
requires std::same_as<SourceSample, std::variant<typename E::Sample...>>
using OneOfEstimators = std::variant<E...>;

class LoopEstimator {
 public:
  LoopEstimator(SampleKind kind, const core::MachineSi& machine, const core::EstimatorSettings& settings) noexcept;

  [[nodiscard]] SampleKind kind() const noexcept { return static_cast<SampleKind>(estimator_.index()); }

  /// Steps one sample of this estimator's kind: true, with the estimate, the time it stands for (for the
  /// validity tracker: the nominal period of a phase sample, the interval since the previous averaged
  /// window — for an instantaneous averaged sample up to estimator.averaged.max_interval_s) and its
  /// summary. A sample of the other kind is not stepped (false).
  bool step(const SourceSample& sample, core::Estimate& estimate, double& dt_s, SampleSummary& summary) noexcept;

  void reset() noexcept;
  /// The next sample starts a new chain; true where that took back what the previous sample adapted (an averaged
  /// chain's unjudged last window: its step flags no longer hold).
  bool resynchronize() noexcept;
  void set_frozen(bool frozen) noexcept;
  void set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept;
  /// Not real-time (a reload).
  void reconfigure(const core::MachineSi& machine, const core::EstimatorSettings& settings) noexcept;

  [[nodiscard]] double psi_m_Wb() const noexcept;
  [[nodiscard]] double r_s_Ohm() const noexcept;
  [[nodiscard]] const core::RpemEstimator& core() const noexcept;

 private:
  using Estimators = OneOfEstimators<core::DriveEstimator, core::AveragedDriveEstimator>;
  static Estimators make(SampleKind kind, const core::MachineSi& machine, const core::EstimatorSettings& settings) noexcept;

  Estimators estimator_;
  double nominal_period_s_;
  double max_interval_s_;
};

}  // namespace rpem::daemon
