#pragma once
// The estimator as every caller uses it (daemon, simulator, offline tools): SI drive samples in,
// SI and pu estimates out. Holds the conditioner (frames, pu, input extensions), the regime classifier
// and RpemEstimator. Samples of a control-rate stream go through the predictor; a sample further than
// max_gap_carry_s (and max_sample_interval_s) after the previous one — a test bench's rows seconds apart —
// is a steady-state observation of its own (docs/derivations.md §13, "Sparse samples").

#include <cstdint>

#include "rpem/core/conditioner.hpp"
#include "rpem/core/drive_sample.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/core/settings.hpp"

namespace rpem::core {

struct Estimate {
  std::int64_t t_ns = 0;
  double psi_m_Wb = 0.0;
  double r_s_Ohm = 0.0;
  Vec2 epsilon_A = Vec2::Zero();  ///< prediction error i − î, rotor frame
  Vec2 i_hat_A = Vec2::Zero();    ///< predicted current, rotor frame
  Vec2 i_meas_A = Vec2::Zero();   ///< measured current, rotor frame (after input corrections)
  double speed_pu = 0.0;
  EstimatorOutput detail;  ///< per-unit detail: θ̂, Ψᵀ, L, code, flags
  Classification regime;   ///< the sample's regime (regime.hpp)
  /// This step undid what the previous sample adapted (an averaged window found mixed by this one, or left unjudged
  /// by this one ending its chain: docs/derivations.md §13, "Mixed windows"): θ̂ is back where it stood before that
  /// sample, and whoever counted its adaptation (its step flags) takes it back.
  bool retracted_previous = false;
};

class DriveEstimator {
 public:
  using Sample = DriveSample;

  DriveEstimator(const MachineSi& machine, const EstimatorSettings& settings) noexcept;

  /// One sample. Real-time safe.
  [[nodiscard]] Estimate step(const DriveSample& sample) noexcept;

  void reset() noexcept;
  /// The next sample starts a new chain. Returns false: nothing this estimator adapted is taken back
  /// (AveragedDriveEstimator's counterpart returns whether a window was).
  bool resynchronize() noexcept;
  void set_frozen(bool frozen) noexcept { core_.set_frozen(frozen); }
  void set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept;
  /// Reloads gains, limits and model extensions, keeping θ̂, Hessians and predictor state.
  void reconfigure(const MachineSi& machine, const EstimatorSettings& settings) noexcept;

  [[nodiscard]] const PerUnitBase& base() const noexcept { return base_; }
  [[nodiscard]] const RpemEstimator& core() const noexcept { return core_; }
  [[nodiscard]] const RegimeClassifier& classifier() const noexcept { return regimes_.classifier(); }
  [[nodiscard]] double psi_m_Wb() const noexcept;
  [[nodiscard]] double r_s_Ohm() const noexcept;
  /// θ̂ = [ψ̂m, r̂s] in pu now (also after reset(), set_estimates() or reconfigure(), before a step).
  [[nodiscard]] const Vec2& theta_pu() const noexcept { return core_.state().theta_pu; }
  [[nodiscard]] bool frozen() const noexcept { return core_.state().frozen; }
  /// The gains' curvature estimates (SGA's r per parameter, GNA's R), for diagnostics.
  [[nodiscard]] const Vec2& sga_hessian_pu() const noexcept { return core_.state().sga_hessian_pu; }
  [[nodiscard]] const Mat2& gna_hessian_pu() const noexcept { return core_.state().gna_hessian_pu; }

 private:
  void configure(const EstimatorSettings& settings) noexcept;
  /// A sample far from the previous one: the steady state of §1 at its own operating point.
  [[nodiscard]] Estimate step_sparse(const DriveSample& sample, const EstimatorSample& conditioned) noexcept;
  /// The sample's voltage as the drive reports it, |u|² [pu].
  [[nodiscard]] double reported_voltage_sq_pu(const DriveSample& sample) const noexcept;
  [[nodiscard]] Estimate estimate(const DriveSample& sample, const EstimatorOutput& detail, const Vec2& i_meas_pu,
                                  double n_pu, Classification regime) const noexcept;

  PerUnitBase base_;
  SampleConditioner conditioner_;
  RpemEstimator core_;
  StreamClassifier regimes_;
  PointGains point_gains_;                 ///< the sparse samples' gains
  GainSequences rates_per_s_;              ///< the configured algorithm's gain rates [1/s] (sparse samples)
  Vec2 dense_rates_per_s_ = Vec2::Zero();  ///< γ_0/T_samp of the step (dense samples)
  double sparse_after_s_ = 0.0;            ///< max(max_sample_interval_s, max_gap_carry_s)
  bool classify_ = true;                   ///< estimator.regimes.enabled
  double inv_voltage_sq_ = 0.0;            ///< 1/U_b²
};

}  // namespace rpem::core
