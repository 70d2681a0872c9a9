#pragma once
// What the estimator tells the thermal filter (docs/derivations.md §14, "Observations"): per step of the
// filter, the load the network is driven by (thermal_network.hpp) and, for ψ̂m and r̂s each, whether it is an
// observation — it adapted through at least half of the step and has settled — with its value, its
// variance from the estimator's own state, its sensitivity to the other, held parameter and its lag.
//
// Per adapted sample, with l the parameter's gain row after scheduling (eq:GainSchedule), g = dî/dθ_j its
// gradient column, g_o the other parameter's, ε the prediction error (all pu):
//   a = l·g                          the fraction of its error the update removes (contraction)
//   settled:   Σ a ≥ settle_time_constants over uninterrupted adaptation (the start's error below e^−Σa)
//   κ = (l·g_o)/a                    θ̂_j − θ_j = κ·(θ_o − θ̂_o) at the update's equilibrium l·ε = 0 (eq. 14.6)
//   σ²_noise = l·Σ_ε·lᵀ / (a·(2 − a))  the stationary variance of θ̂_j, Σ_ε the residuals' long-run covariance
//                                      (their spectral density at zero: the update is a low-pass) (eq. 14.7)
//   σ²_model = |ε̄_⊥|²·|l|²/a²        the bias a model error as large as the mean residual the update cannot
//                                      remove (ε̄_⊥ ⊥ l), in the direction it would remove, causes (eq. 14.8)
//   τ = Δt/a                          the tracking time constant
// ε̄ and Σ_ε are exponentially weighted over residual_time_constant_s, Σ_ε by batch means: M times the
// covariance of the means of M consecutive residuals, a batch closing after a quarter of the estimator's time
// constant (Σa ≥ ¼) or kMaxBatch samples — long against the noise's correlation, short against what the
// estimator itself moves (a differenced noise, which the averaged path's inductive correction puts into ε
// and which the update does not see, keeps 2/M of its variance; rows seconds apart, a ≈ 1: M = 1). A step's observation is the mean of its
// adapted samples' values, κ, variances and τ; nothing here depends on the thermal model. A sample whose adaptation
// the estimator takes back afterwards (Estimate::retracted_previous: an averaged window found mixed, docs/derivations.md
// §13, "Mixed windows") is taken out again — of the step, the settling and the residual statistics — unless its step
// has already completed. Real-time safe.

#include <array>
#include <cstdint>
#include <limits>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/thermal_network.hpp"

namespace rpem::core {

struct ThermalObserverConfig {
  double period_s = 1.0;                   ///< one filter step at least this long
  double residual_time_constant_s = 10.0;  ///< ε̄ and Σ_ε
  double settle_time_constants = 5.0;      ///< Σa before a parameter is an observation
};

/// What the thermal block needs of a sample besides its Estimate.
struct ThermalSample {
  double dt_s = 0.0;  ///< the time the sample stands for (since the previous one)
  /// Measured; NaN: none with this sample (a log's empty cell, a CAN sample whose coolant frame did not come this
  /// time): the newest earlier reading holds, and before the first one the configured coolant stands in.
  double coolant_C = std::numeric_limits<double>::quiet_NaN();
  double winding_sensor_C = std::numeric_limits<double>::quiet_NaN();  ///< NaN: none
};

/// One parameter's observation over a step, SI (Wb for ψm, Ω for R_s).
struct ParameterObservation {
  bool valid = false;
  double value = 0.0;       ///< mean estimate over the adapted samples
  double cross = 0.0;       ///< κ in SI: the value's change per unit error of the other parameter
  double other_held = 0.0;  ///< the other parameter's estimate (its held value)
  double variance = 0.0;    ///< σ²_noise + σ²_model [SI²]
  double variance_noise = 0.0;
  double time_constant_s = 0.0;
  double sample_dt_s = 0.0;  ///< the mean Δt of the adapted samples (a row, or an averaged log's window)
};

/// When a step's readings were taken, as their mean and variance of age at the step's end (weighted as the
/// reading's mean is, by the time each stands for). A log's temperatures are readings at their row's t
/// (docs/drive-log.md), so rows 0.5 s apart in a 1 s step are 0.25 s old on average, not the Δt/2 of a mean
/// over the step; {Δt/2, Δt²/12} is that continuous mean, {0, 0} one reading at the step's end.
struct ReadingAge {
  double mean_s = 0.0;
  double variance_s2 = 0.0;
};

/// One step of the thermal filter.
struct ThermalStepData {
  std::int64_t t_ns = 0;  ///< the step's end (its last sample)
  ThermalLoad load;
  std::array<ParameterObservation, 2> parameter;                       ///< indexed by kPsiM, kRs
  double winding_sensor_C = std::numeric_limits<double>::quiet_NaN();  ///< the step's mean; NaN: none
  ReadingAge winding_sensor_age;                                       ///< when its readings were taken
  bool coolant_read = false;             ///< a sample of the step carried a coolant reading (ThermalFilter::coolant_read)
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0;  ///< the estimates at the step's end
};

class ThermalObserver {
 public:
  /// `coolant_C`: the temperature used until a sample carries a reading (ThermalSample::coolant_C).
  ThermalObserver(const ThermalObserverConfig& config, const PerUnitBase& base, const MachineSi& machine,
                  const LossBase& loss_base, double coolant_C) noexcept;

  /// One estimator sample; true when it completed a step (then step() holds it).
  bool add(const Estimate& e, const ThermalSample& s) noexcept;
  [[nodiscard]] const ThermalStepData& step() const noexcept { return step_; }
  /// The newest sample's adaptation was taken back (Estimate::retracted_previous, or a resynchronize() that
  /// retracted): what it taught is taken out, but for the sums of a step it completed. Once: a second call changes
  /// nothing.
  void retract_last() noexcept;
  /// Forgets the settling and the residual statistics (an estimator reset or new initial values).
  void restart() noexcept;
  void reconfigure(const ThermalObserverConfig& config, const PerUnitBase& base, const MachineSi& machine,
                   const LossBase& loss_base, double coolant_C) noexcept;

 private:
  struct Accumulated {
    double adapted_s = 0.0, value = 0.0, cross = 0.0, other = 0.0, variance = 0.0, variance_noise = 0.0, tau = 0.0;
    int samples = 0;
  };
  static constexpr int kMaxBatch = 32;
  /// What the adapted samples teach: the step's sums, the settling and ε̄, Σ_ε — what a retraction takes back.
  struct Learnt {
    std::array<Accumulated, 2> acc{};
    std::array<double, 2> settled{};  ///< Σa over the current uninterrupted adaptation
    Vec2 eps_mean = Vec2::Zero();     ///< ε̄, per sample
    Vec2 batch_sum = Vec2::Zero();    ///< the current batch's residuals
    double batch_dt_s = 0.0, batch_a = 0.0;
    int batch_count = 0;
    Vec2 batch_mean = Vec2::Zero();  ///< the batch means' mean
    Mat2 eps_cov = Mat2::Zero();     ///< Σ_ε = kBatch·Cov(batch means)
    bool eps_started = false, batch_started = false;
  };
  void add_parameter(int j, const Estimate& e, double dt_s) noexcept;
  /// ε̄ and Σ_ε (batch means) from an adapted sample's residual.
  void add_residual(const EstimatorOutput& d, double dt_s) noexcept;

  ThermalObserverConfig config_;
  PerUnitBase base_;
  MachineSi machine_;
  LossBase loss_base_;
  double coolant_C_;
  double measured_coolant_C_ = std::numeric_limits<double>::quiet_NaN();  ///< the newest reading; NaN: none yet
  bool coolant_read_ = false;                                             ///< in the current step
  LossAccumulator losses_;
  Learnt learnt_;
  Learnt before_last_;               ///< learnt_ before the newest sample
  bool stepped_since_last_ = false;  ///< the newest sample completed a step (its sums are published)
  // The sensor's readings: Σw·T, Σw, and Σw·τ, Σw·τ² of their times τ since the step's start (w: the time each stands for).
  double sensor_sum_ = 0.0, sensor_time_ = 0.0, sensor_elapsed_ = 0.0, sensor_elapsed_sq_ = 0.0;
  ThermalStepData step_;
};

}  // namespace rpem::core
