#pragma once
// The Ψᵀ-based recursive prediction error estimator of ψm and r_s, per-unit, rotor frame.
//
//   θ̂[k] = [ θ̂[k−1] + L[k]·ε[k] ]_{D_M}                        (eq_RPEM_intro)
//   ε[k] = i[k] − î[k, θ̂[k−1]]                                  (open-loop prediction error)
//
// One call of step() is one sample: predict (predictor.hpp), form Ψᵀ (dynamic or steady state),
// compute L (gain.hpp), schedule it (eq:GainSchedule), update and project (eq:paramsubset).
// step() is real-time safe: noexcept, no allocation, no locks, no system calls.

#include <array>
#include <cstdint>

#include "rpem/core/gain.hpp"
#include "rpem/core/machine.hpp"
#include "rpem/core/predictor.hpp"
#include "rpem/core/scheduler.hpp"
#include "rpem/core/types.hpp"

namespace rpem::core {

enum class GradientForm : std::uint8_t { kSteadyState = 0, kDynamic = 1 };

/// What the user's EstimatorSettings (settings.hpp) and the per-unit EstimatorConfig share, with their
/// defaults — written once, here; the YAML reader (io) takes its defaults from a default-constructed one.
struct EstimatorOptions {
  /// The default max_sample_interval_s in nominal periods (8 × 125 µs = 1 ms).
  static constexpr double kMaxSampleIntervalPeriods = 8.0;

  Algorithm algorithm = Algorithm::kSga;
  Discretization discretization = Discretization::kTrapezoidal;
  GradientForm gradient_psi_m = GradientForm::kSteadyState;
  GradientForm gradient_r_s = GradientForm::kSteadyState;
  std::array<GainSequences, 3> gains{};  ///< indexed by Algorithm
  GainFloors floors;
  Vec2 initial_sga_hessian_pu = Vec2::Zero();                         ///< r[0] per parameter
  Mat2 initial_gna_hessian_pu = Mat2::Zero();                         ///< R[0]
  double nominal_sample_period_s = 125e-6;                            ///< the period the γ_0 refer to; γ scales with dt
  double max_sample_interval_s = kMaxSampleIntervalPeriods * 125e-6;  ///< longer: the predictor resynchronises
  double max_gap_carry_s = 20e-3;                                     ///< across a shorter gap the prediction error is kept
  /// ν_max: a sample whose prediction error lies further than ν_max of its noise beyond what any θ in D_M
  /// explains is skipped (StepCode::kOutlier; docs/derivations.md §14); 0: never.
  double outlier_bound_sigma = 5.0;
  bool adapt_psi_m = true;
  bool adapt_r_s = true;
};

struct EstimatorConfig : EstimatorOptions {
  MachinePu model;             ///< nominal model; x_d, x_q are used as they are
  double omega_n_rad_s = 0.0;  ///< ω_n, the electrical base speed
  SchedulerConfig scheduler;
  ParameterBounds bounds;
  Vec2 initial_theta_pu = Vec2::Zero();
  double max_predicted_current_pu = 20.0;  ///< |î| beyond this counts as divergence
};

/// One conditioned sample (see conditioner.hpp): the interval since the previous sample and the
/// current measured at its end.
struct EstimatorSample {
  PredictorInterval interval;  ///< with resync: dt_s is the gap since the last sample (0: none known)
  Vec2 i_meas_pu = Vec2::Zero();
  bool resync = false;  ///< first sample, or samples were lost before this one
  /// Model inductances at this sample's current (the saturation extensions); 0: the configured ones.
  double x_d_pu = 0.0;
  double x_q_pu = 0.0;
};

/// One averaged (or slowly sampled) rotor-frame sample for the steady-state model (docs/derivations.md
/// §11): the voltage as the machine sees it, the measured current, the mean speed, pu.
struct SteadyStateSample {
  double dt_s = 0.0;         ///< time since the previous sample (scales the gains)
  Vec2 u_pu = Vec2::Zero();  ///< rotor-frame voltage, input corrections applied
  Vec2 i_meas_pu = Vec2::Zero();
  double n_pu = 0.0;  ///< mean speed over the sample's window
  /// Where Ψᵀ (and PhyInt's denominators) are evaluated: an instrument — the operating point of the
  /// preceding samples, whose noise is independent of this sample's (docs/derivations.md §11).
  Vec2 i_gradient_pu = Vec2::Zero();
  double n_gradient_pu = 0.0;
  bool resync = false;  ///< no update: first sample, or samples were lost before this one
  /// Model inductances at this sample's current (the saturation extensions); 0: the configured ones.
  double x_d_pu = 0.0;
  double x_q_pu = 0.0;
};

/// Stable result codes; they are published in diagnostics (numbers never change).
enum class StepCode : std::uint8_t {
  kAdapted = 0,            ///< prediction, gradient and update done (the update may be scheduled out)
  kSynchronized = 1,       ///< predictor (re)initialised from this measurement; no update
  kRejectedNonFinite = 2,  ///< NaN or Inf in the sample; ignored, predictor will resynchronise
  kPredictorDiverged = 3,  ///< |î| exceeded its bound; predictor resynchronised
  kExcluded = 4,           ///< its regime excludes it (regime.hpp): predicted, nothing adapted
  kOutlier = 5,            ///< its prediction error is beyond the outlier bound: predicted, skipped
};

/// What a sample's regime (regime.hpp) lets it do, and the noise its prediction error is judged against.
/// The default admits everything and judges nothing (the estimator as the paper states it).
struct Admission {
  bool adapt = true;  ///< false: excluded — predicted, nothing adapted
  bool psi_m = true;  ///< ψm's term is excited (on top of eq:GainSchedule)
  bool r_s = true;    ///< r_s' term is excited
  /// Judge the prediction error against the outlier bound, with the sample's noise variances [pu²].
  bool judge = false;
  double var_u_pu = 0.0, var_i_pu = 0.0, var_n_pu = 0.0;
};

namespace step_flag {
inline constexpr std::uint16_t kGainFloored = 1U << 0;    ///< gain_flag::kFloored
inline constexpr std::uint16_t kPseudoInverse = 1U << 1;  ///< gain_flag::kPseudoInverse
inline constexpr std::uint16_t kProjectedPsiM = 1U << 2;  ///< ψ̂m clamped to D_M
inline constexpr std::uint16_t kProjectedRs = 1U << 3;    ///< r̂s clamped to D_M
inline constexpr std::uint16_t kFrozen = 1U << 4;         ///< adaptation frozen by command
inline constexpr std::uint16_t kPsiMActive = 1U << 5;     ///< ψ̂m adapted in this sample
inline constexpr std::uint16_t kRsActive = 1U << 6;       ///< r̂s adapted in this sample
}  // namespace step_flag

struct EstimatorState {
  Vec2 theta_pu = Vec2::Zero();  ///< θ̂ = [ψ̂m, r̂s]
  PredictorState predictor;
  Vec2 sga_hessian_pu = Vec2::Zero();
  Mat2 gna_hessian_pu = Mat2::Zero();
  bool synchronized = false;
  bool frozen = false;
  Vec2 last_epsilon_pu = Vec2::Zero();  ///< ε of the last adapted sample
  bool epsilon_valid = false;
};

struct EstimatorOutput {
  Vec2 theta_pu = Vec2::Zero();
  Vec2 epsilon_pu = Vec2::Zero();
  Vec2 i_hat_pu = Vec2::Zero();
  Mat2 gradient = Mat2::Zero();  ///< Ψᵀ used for the gain
  Mat2 gain = Mat2::Zero();      ///< L after scheduling
  StepCode code = StepCode::kSynchronized;
  std::uint16_t flags = 0;
};

/// Rates [1/s] as the gains of a window dt long: γ = 1 − e^{−rate·dt} (docs/derivations.md §11).
[[nodiscard]] Vec2 per_interval(const Vec2& rate_per_s, double dt_s) noexcept;

/// Gains for point observations at uneven intervals (docs/derivations.md §13, "Sparse samples"):
/// exponentially weighted least squares that weighs each observation 1 and the past by e^{−rate·dt},
///   γ_k = 1/S_k,   S_k = 1 + e^{−rate·(t_k − t_{k−1})}·S_{k−1},   S_0 = 1/(1 − e^{−rate·T_nom})
/// over the observations that adapted (the start weighs a full memory of nominal samples). Evenly spaced:
/// γ → 1 − e^{−rate·dt}, per_interval()'s; spaced far beyond the time constant 1/rate: γ → 1. Per parameter,
/// for the Hessian's and the step's rates.
struct PointGains {
  GainSequences weight;      ///< S per rate (the counted observations' decayed weight)
  std::int64_t last_ns = 0;  ///< the last counted observation
  bool counted = false;
  void start(const GainSequences& rates_per_s, double nominal_period_s) noexcept;
  /// The gains of an observation at t_ns; nothing changes until count(). Real-time safe.
  [[nodiscard]] GainSequences at(const GainSequences& rates_per_s, std::int64_t t_ns) const noexcept;
  /// Counts the observation at t_ns that took `gains` (from at()). Real-time safe.
  void count(const GainSequences& gains, std::int64_t t_ns) noexcept;
};

class RpemEstimator {
 public:
  explicit RpemEstimator(const EstimatorConfig& config) noexcept;

  /// One sample. Real-time safe.
  EstimatorOutput step(const EstimatorSample& sample) noexcept { return step(sample, Admission{}); }
  /// One sample with its admission: an excluded one re-anchors the predictor on the measurement (its
  /// model, not the machine, failed) and adapts nothing; a judged outlier adapts nothing. Real-time safe.
  EstimatorOutput step(const EstimatorSample& sample, const Admission& admission) noexcept;

  /// One averaged sample with the steady-state model instead of the predictor (docs/derivations.md §11):
  ///   î = M̂⁻¹·(u − [0, n·ψ̂m]ᵀ)  (§1),  ε = i − î,  Ψᵀ = the steady-state forms (§3) at the
  /// sample's instrument (i_gradient, n_gradient), then the same gain, eq:GainSchedule and projection as step(). `rates_per_s` are the gain
  /// sequences as rates [1/s]; a sample dt_s after the previous one uses γ = 1 − e^{−rate·dt}.
  /// Real-time safe.
  EstimatorOutput step_steady_state(const SteadyStateSample& sample, const GainSequences& rates_per_s) noexcept;
  /// The same with the sample's gains given (per parameter: the Hessian's γ_r and the step γ_L) and its
  /// admission. Real-time safe.
  EstimatorOutput step_steady_state(const SteadyStateSample& sample, const Vec2& gamma_r, const Vec2& gamma_l,
                                    const Admission& admission) noexcept;

  /// θ̂ and the Hessians back to their initial values; the predictor resynchronises. Real-time safe.
  void reset() noexcept;
  /// The next sample re-initialises the predictor from the measurement. Real-time safe.
  void resynchronize() noexcept { state_.synchronized = false; }
  /// Seeds θ̂ (projected onto D_M), e.g. from persisted estimates. Real-time safe.
  void set_theta(const Vec2& theta_pu) noexcept;
  /// Freezes or releases adaptation; prediction continues. Real-time safe.
  void set_frozen(bool frozen) noexcept { state_.frozen = frozen; }

  /// What adapting on a sample changes: θ̂, the Hessians and the last adapted ε.
  struct Adaptation {
    Vec2 theta_pu = Vec2::Zero();
    Vec2 sga_hessian_pu = Vec2::Zero();
    Mat2 gna_hessian_pu = Mat2::Zero();
    Vec2 last_epsilon_pu = Vec2::Zero();
    bool epsilon_valid = false;
  };
  [[nodiscard]] Adaptation adaptation() const noexcept {
    return {state_.theta_pu, state_.sga_hessian_pu, state_.gna_hessian_pu, state_.last_epsilon_pu, state_.epsilon_valid};
  }
  /// Back to an adaptation saved before the samples it undoes (a window found mixed afterwards,
  /// docs/derivations.md §13); the predictor is left as it is. Real-time safe.
  void retract(const Adaptation& before) noexcept {
    state_.theta_pu = before.theta_pu;
    state_.sga_hessian_pu = before.sga_hessian_pu;
    state_.gna_hessian_pu = before.gna_hessian_pu;
    state_.last_epsilon_pu = before.last_epsilon_pu;
    state_.epsilon_valid = before.epsilon_valid;
  }
  /// Replaces gains, floors, scheduler, bounds and algorithm while keeping θ̂, Hessians and the
  /// predictor (SIGHUP reload). Not real-time: call between steps from the owning thread.
  void reconfigure(const EstimatorConfig& config) noexcept;

  [[nodiscard]] const EstimatorConfig& config() const noexcept { return config_; }
  [[nodiscard]] const EstimatorState& state() const noexcept { return state_; }

 private:
  /// Re-anchors the predictor on the measurement. Across a short gap in a running stream it keeps the
  /// last prediction error (î = i − ε), which the open-loop predictor needs a time constant to rebuild.
  void synchronize(const EstimatorSample& sample, const MachinePu& model) noexcept;
  /// The configured model with the current estimates and the sample's inductances, if it has any (> 0).
  [[nodiscard]] MachinePu model_for(double x_d_pu, double x_q_pu) const noexcept;
  /// What one sample brings to the update: the model it was predicted with, the speed eq:GainSchedule
  /// reads, the current PhyInt's denominators use (the prediction î, or the averaged path's instrument),
  /// ε, î and the prediction gradient ψ.
  struct Update {
    MachinePu model;
    double n_pu;
    Vec2 i_gain_pu, epsilon_pu, i_hat_pu;
    Mat2 gradient;
    /// A steady-state sample (a window, a point observation): its gain is not small, and GNA takes the Newton step
    /// of the one parameter the schedule lets adapt (gna_gain's `only`; docs/derivations.md §5).
    bool steady_state;
  };
  /// The update both sample kinds share: gain (SGA, GNA, PhyInt), eq:GainSchedule, θ̂ += L·ε, projection
  /// onto D_M (eq:paramsubset); the sample's output.
  EstimatorOutput update(const Update& u, const Vec2& gamma_r, const Vec2& gamma_l, const Admission& admission) noexcept;
  /// Whether ε lies beyond the bound: its evidence Ψ_jᵀε on a parameter further than ν_max of its noise
  /// beyond the largest a θ in D_M gives (docs/derivations.md §14).
  [[nodiscard]] bool outlier(const Update& u, const Admission& admission) const noexcept;
  /// Per parameter, |Ψ_jᵀε| less the largest Ψ_jᵀΨ·Δθ over D_M (> 0: the noise decides).
  [[nodiscard]] Vec2 beyond_explained(const Update& u) const noexcept;
  /// Whether a `beyond` > 0 exceeds ν_max times the evidence's noise.
  [[nodiscard]] bool beyond_noise(const Update& u, const Admission& admission, const Vec2& beyond) const noexcept;
  /// The output of a sample predicted but not adapted (excluded, outlier): ε and î as predicted.
  [[nodiscard]] EstimatorOutput predicted_only(StepCode code, const Vec2& epsilon, const Vec2& i_hat) const noexcept;
  [[nodiscard]] Mat2 select_gradient(const MachinePu& model, double n_pu) const noexcept;
  /// The output of a sample that made no update: θ̂ and î as they stand.
  [[nodiscard]] EstimatorOutput held(StepCode code) const noexcept;

  EstimatorConfig config_;
  EstimatorState state_;
  // Decided by reconfigure(), so the per-sample path does not re-derive them.
  PredictorCoefficients coefficients_;      ///< from config_.model
  double inverse_nominal_period_ = 0.0;     ///< 1/T_samp
  double inverse_r_min_ = 0.0;              ///< 1/r_min of D_M (the outlier bound)
  Gradients gradients_ = Gradients::kSkip;  ///< whether predict() advances the dynamic gradients
  double scaled_for_dt_s_ = -1.0;           ///< the interval gamma_r_, gamma_l_ were scaled for
  Vec2 gamma_r_ = Vec2::Zero(), gamma_l_ = Vec2::Zero();
};

}  // namespace rpem::core
