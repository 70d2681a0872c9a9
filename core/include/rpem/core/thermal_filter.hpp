#pragma once
// The Kalman filter of the node temperatures (docs/derivations.md §14, "Fusion"): the thermal network as its
// process model, augmented by each node's heat disturbance d [W] — what the loss model gets wrong — and by
// the temperature laws' calibration errors and the held coolant reading's error c, which it carries but does not
// estimate (Schmidt's "consider" states: nothing in the data tells a calibration error from a model error, nor a
// coolant that moved unread from a heat disturbance), corrected by scalar linear observations (a parameter
// estimate through its temperature law, a sensor).
//
//   state x = [T; d; c],  T⁺ = Φ·T + γ + Γ_d·(d + g_c·e_c),  d⁺ = a·d + v,  c⁺ = c + [0 0 0 0 w_c]
//                                                                          (eq. 14.4, 14.9, 14.19, 14.29)
//   a = e^{−Δt/τ_d} per node: a first-order Gauss–Markov disturbance, τ_d = ∞ (a = 1) the random walk
//   c = [e_ref,magnet, e_α,magnet, e_ref,copper, e_α,copper, e_c]: a law's temperature reads T + e_ref + e_α·(T − T_ref);
//   e_c [K] the coolant's move since its newest reading, which heats node i by g_c,i·e_c = G_i0(ω)·e_c (eq. 14.1):
//   a random walk, Var(w_c) = q_c·Δt once a reading has been seen, and a new reading starts it again at zero
//   (coolant_read: the coolant's error is then the sensor's, independent of every earlier error)
//   Var(v_i) = q_d,i·(τ_d/2)·(1 − a²) [→ q_d,i·Δt as τ_d → ∞] + Σ_terms (σ_rel,term·ΔP_term,i)²: a loss model's error moves with the loss it
//   models, so each change ΔP of a modelled loss term between steps adds its relative uncertainty squared
//   P⁺ = F·P·Fᵀ + Q_d,  F = [Φ Γ_d B; 0 A 0; 0 0 I] (A = diag a; B zero but for Γ_d·g_c in e_c's column),
//        Q_d = (Δt/2)·(Φ·Q_T·Φᵀ + Q_T) on T (trapezoidal rule), Var(v) on d, q_c·Δt on e_c,
//        formed blockwise: only the rows and columns of T change (eq. 14.12)
//   observe:  y = h·T + h_d·d + h_c·c + offset + v_y,  v_y ~ N(0, r);  ν = y − ŷ,  s = H·P·Hᵀ + r
//             K = [P_xx·Hᵀ/s on T and d; 0 on c],  x += K·ν,  P −= rank-one terms of that gain (eq. 14.11)
//
// An observation whose innovation lies beyond `gate_sigma`·√s is rejected (counted by the caller), so one
// wild estimate cannot pull the state. Real-time safe: fixed size, noexcept, no allocation.

#include <limits>

#include "rpem/core/thermal_network.hpp"

namespace rpem::core {

inline constexpr int kCalibrationStates = 5;
/// T and d: what the model moves and the filter estimates; the calibration states follow them.
inline constexpr int kDynamicThermalStates = 2 * kMaxThermalNodes;
inline constexpr int kThermalStates = kDynamicThermalStates + kCalibrationStates;
using ThermalStateVec = Eigen::Matrix<double, kThermalStates, 1>;
using ThermalStateMat = Eigen::Matrix<double, kThermalStates, kThermalStates>;
using CalibrationVec = Eigen::Matrix<double, kCalibrationStates, 1>;

/// The consider states: which law, and offset or coefficient; and the held coolant reading's error e_c (eq. 14.29).
enum class Calibration : int {
  kMagnetOffset = 0,
  kMagnetCoefficient = 1,
  kCopperOffset = 2,
  kCopperCoefficient = 3,
  kCoolantError = 4
};

/// One scalar observation y = h·T + h_d·d + h_c·c + offset + b·δT_i·δc_k + v, v ~ N(0, variance); δ the errors of
/// the prior mean. The bilinear term is a law's e_α·(T − T_ref) beyond its linearisation at T̂ (eq. 14.10, 14.10a).
struct ThermalObservation {
  ThermalVec h = ThermalVec::Zero();
  ThermalVec h_d = ThermalVec::Zero();  ///< [K/W] on the heat disturbances: a sensor that sees a rate (eq. 14.22)
  CalibrationVec h_c = CalibrationVec::Zero();
  double offset = 0.0;
  double value = 0.0;
  double variance = 0.0;
  double bilinear = 0.0;                                         ///< b (0: none)
  int bilinear_node = 0;                                         ///< i
  Calibration bilinear_state = Calibration::kMagnetCoefficient;  ///< k
};

/// kRejectedHeld: a reading that holds one value (thermal_held_reading.hpp), never offered to the filter.
enum class ObservationResult : std::uint8_t { kAccepted = 0, kRejectedGate = 1, kRejectedInvalid = 2, kRejectedHeld = 3 };

struct ThermalFilterConfig {
  ThermalNetwork network;
  ThermalVec process_noise_K2_per_s = ThermalVec::Zero();  ///< Q_T: white noise on each node's dT/dt
  ThermalVec disturbance_W2_per_s = ThermalVec::Zero();    ///< q_d: the heat disturbances' drift
  /// τ_d: the disturbances' correlation time (eq. 14.19); +∞ (the default) is the random walk.
  ThermalVec disturbance_time_constant_s = ThermalVec::Constant(std::numeric_limits<double>::infinity());
  /// σ_rel of each fitted loss term (form row, node column): its relative uncertainty.
  Eigen::Matrix<double, kLossForms, kMaxThermalNodes> loss_rel_sigma =
      Eigen::Matrix<double, kLossForms, kMaxThermalNodes>::Zero();
  double copper_rel_sigma = 0.1;  ///< σ_rel of the copper loss (R_s's law and reference)
  /// σ of the calibration states at the start (Calibration order): [K, relative, K, relative, K]; the coolant's
  /// error starts at 0, the configured coolant standing in until a reading comes.
  CalibrationVec calibration_sigma = (CalibrationVec() << 1.0, kNdFeB.rel_sigma(), 1.0, kCopper.rel_sigma(), 0.0).finished();
  /// q_c [K²/s]: how fast an unread coolant may move, as a random walk (eq. 14.29); 0: a held reading is exact.
  double coolant_drift_K2_per_s = 0.0;
  double gate_sigma = 5.0;
  /// After this many consecutive rejected observations of one kind the model, not the observation, is taken
  /// to be wrong: the observed node's variance grows by ν²/h² and the observation is applied (0: never).
  int gate_reset_after = 3;
};

class ThermalFilter {
 public:
  explicit ThermalFilter(const ThermalFilterConfig& config) noexcept : config_(config) {}

  /// Every node at `t_C` with standard deviation `sigma_K` (a soaked machine), no disturbance.
  void reset(double t_C, double sigma_K) noexcept;
  /// Starts from given temperatures (disturbances zero) with this covariance of the temperatures.
  void set_temperatures(const ThermalVec& t_C, const ThermalMat& p) noexcept;
  /// Advances by load.dt_s under `load` (nothing when dt_s ≤ 0).
  void predict(const ThermalLoad& load) noexcept { predict(load, thermal_rates(config_.network, load)); }
  /// The same with the load's rates (thermal_rates(network, load)) formed by the caller.
  void predict(const ThermalLoad& load, const ThermalRates& rates) noexcept;
  /// Applies one observation unless it is not finite or its innovation lies beyond the gate.
  [[nodiscard]] ObservationResult observe(const ThermalObservation& o) noexcept;
  /// A coolant reading came in the step just predicted: the coolant's error e_c starts again, at zero and
  /// uncorrelated (eq. 14.29); from now on it walks between readings. Call after predict().
  void coolant_read() noexcept;
  /// Adds `variance_K2` to one node's variance (the model has drifted: a gate reset).
  void inflate(int node, double variance_K2) noexcept { p_(node, node) += variance_K2; }
  /// Moves [T; d] to the given values and widens the temperatures' covariance by δ·δᵀ, δ their move, so the band
  /// covers both; the disturbances are replaced, not widened (what a held reading had told the filter is
  /// withdrawn: its disturbances were learnt from it; thermal_held_reading.hpp, eq. 14.28a).
  void withdraw_to(const ThermalVec& t_C, const ThermalVec& d_W) noexcept;
  /// s = H·P·Hᵀ + r of an observation at the current state (what observe() gates by).
  [[nodiscard]] double innovation_variance(const ThermalObservation& o) const noexcept;
  /// Runs [T; d] through the newest prediction's transition, noise-free: T⁺ = Φ·T + γ + Γ_d·d, d⁺ = a·d (an
  /// open-loop copy of the network beside the filter). Nothing before the first prediction.
  void advance_open_loop(ThermalVec& t_C, ThermalVec& d_W) const noexcept;
  /// Replaces the model (a reload), keeping the state.
  void reconfigure(const ThermalFilterConfig& config) noexcept { config_ = config; }

  [[nodiscard]] ThermalVec temperature_C() const noexcept { return x_.head<kMaxThermalNodes>(); }
  [[nodiscard]] ThermalVec disturbance_W() const noexcept { return x_.segment<kMaxThermalNodes>(kMaxThermalNodes); }
  [[nodiscard]] const ThermalStateMat& covariance() const noexcept { return p_; }
  [[nodiscard]] double sigma_K(int node) const noexcept;
  [[nodiscard]] const ThermalFilterConfig& config() const noexcept { return config_; }
  /// The last observation's innovation ν and its variance s.
  [[nodiscard]] double last_innovation() const noexcept { return innovation_; }
  [[nodiscard]] double last_innovation_variance() const noexcept { return innovation_variance_; }

 private:
  using LossTerms = Eigen::Matrix<double, kLossForms + 1, kMaxThermalNodes>;
  /// The modelled loss terms of each node under `l` at the state's winding temperature: copper, then the forms.
  [[nodiscard]] LossTerms loss_terms(const ThermalLoad& l) const noexcept;
  /// a = P·Hᵀ of an observation, and s from it.
  [[nodiscard]] ThermalStateVec cross_covariance(const ThermalObservation& o) const noexcept;
  [[nodiscard]] double innovation_variance(const ThermalObservation& o, const ThermalStateVec& a) const noexcept;

  ThermalFilterConfig config_;
  ThermalStateVec x_ = ThermalStateVec::Zero();
  ThermalStateMat p_ = ThermalStateMat::Zero();
  LossTerms previous_terms_ = LossTerms::Zero();
  ThermalTransition transition_{};         ///< the newest prediction's (advance_open_loop)
  ThermalVec decay_ = ThermalVec::Ones();  ///< its disturbances' a
  bool predicted_ = false;
  bool coolant_seen_ = false;  ///< a coolant reading has come: e_c walks (eq. 14.29)
  double innovation_ = 0.0, innovation_variance_ = 0.0;
};

}  // namespace rpem::core
