#pragma once
// Both temperatures at every moment (docs/thermal.md): the thermal network's Kalman filter (thermal_filter.hpp)
// driven by the losses of the estimator's samples and corrected by what the estimator observes
// (thermal_observer.hpp) — the magnet temperature from ψ̂m, the winding's from r̂s, each only while it adapts
// and has settled — and by a winding sensor where there is one. The same block runs in rpemd's loop and in
// `rpem estimate --thermal`.
//
// The observations through the temperature laws (core/thermal.hpp; docs/derivations.md §14, eq. 14.5–14.8):
//   ψ̂m = ψ_ref·(1 + α_m·(T_m' − T_ref)) + κ_ψ·(R_s(T_w) − r̂s)    while ψ̂m adapts (r̂s held)
//   r̂s = R_ref·(1 + α_cu·(T_w' − T_ref)) + κ_r·(ψm(T_m) − ψ̂m)    while r̂s adapts (ψ̂m held)
//   T_sensor = T_w, or with a lagging sensor its step's mean T_w − κ·dT_w/dt − β·e (thermal_sensor.hpp, eq. 14.22)
// where T' = T + e_ref + e_α·(T − T_ref) is what a law with calibration errors e reads (the filter's consider
// states), with the variance of the estimator's own state (σ²_noise + σ²_model) and of the tracking lag
// σ_T,lag = |dT̂/dt|·τ through the law's slope. Real-time safe.

#include <array>
#include <cmath>
#include <cstdint>

#include "rpem/core/thermal_filter.hpp"
#include "rpem/core/thermal_held_reading.hpp"
#include "rpem/core/thermal_observer.hpp"
#include "rpem/core/thermal_resume.hpp"
#include "rpem/core/thermal_sensor.hpp"

namespace rpem::core {

struct ThermalFusionConfig {
  ThermalFilterConfig filter;  ///< the network (its copper law is R_s's), the noises, the laws' calibration σ
  DriftLaw magnet_law;         ///< ψm(T_magnet) [Wb]
  ThermalObserverConfig observer;
  double coolant_C = 25.0;                      ///< where the samples carry no coolant temperature
  double winding_sensor_sigma_K = 0.0;          ///< a winding sensor's σ; 0: sensor not used
  double winding_sensor_time_constant_s = 0.0;  ///< its lag τ_s behind the winding (eq. 14.22, 14.24); 0: none
  /// What the network's winding node stands for: false, the winding (the sensor lags it, eq. 14.22); true, the
  /// sensor's reading, which the winding leads: T_w = T_node + τ_s·dT_node/dt (eq. 14.24).
  bool winding_node_is_reading = false;
  double initial_sigma_K = 10.0;  ///< σ of every node at the start (the coolant's temperature)
};

/// Two sensors at one temperature differ by more than this many σ once in 370 (two-sided normal): the soak test.
inline constexpr double kSoakBound_sigma = 3.0;

/// The soak test at a start (docs/thermal.md, "A log that does not start soaked"): the winding sensor's distance
/// from the coolant where it exceeds kSoakBound_sigma of the sensor's σ — the machine is not soaked, and no node's
/// temperature is known from the coolant — else 0.
[[nodiscard]] inline double unsoaked_excess_K(double winding_sensor_C, double coolant_C, double sensor_sigma_K) noexcept {
  const double excess_K = winding_sensor_C - coolant_C;
  return std::abs(excess_K) > kSoakBound_sigma * sensor_sigma_K ? excess_K : 0.0;
}

/// Where the network starts at a log's or a run's first step: every node at the coolant (a soaked machine), the
/// winding at its sensor where the configuration fuses one and the step has a reading — and every node there where
/// the reading says the machine is not soaked (unsoaked_excess_K). ThermalFusion starts here; so do the fit's replays.
[[nodiscard]] ThermalVec start_temperatures_C(const ThermalFusionConfig& c, const ThermalStepData& s) noexcept;

/// A node's fused temperature.
struct ThermalNodeEstimate {
  double t_C = 0.0;
  double sigma_K = 0.0;
  bool observed = false;  ///< an observation of this node was applied in the newest step
  double age_s = -1.0;    ///< since the last one; −1: never
};

struct ThermalEstimate {
  std::int64_t t_ns = 0;  ///< the newest step's end
  bool started = false;   ///< at least one step
  /// The filter started every node at the coolant, an assumption nothing tested: no state resumed and no fused
  /// winding reading in its first step (start_temperatures_C).
  bool start_assumed_soaked = false;
  int nodes = 0, winding = 0, magnet = 1;
  std::array<ThermalNodeEstimate, kMaxThermalNodes> node{};
  /// The inverse laws of the current estimates (what the estimator alone says, held where it does not adapt).
  double t_magnet_rpem_C = 0.0, t_winding_rpem_C = 0.0;
  double coolant_C = 0.0;  ///< the newest step's mean
  std::int64_t observations_accepted = 0;
  std::int64_t observations_rejected = 0;  ///< beyond the gate (gate_sigma) or not finite
  std::int64_t gate_resets = 0;            ///< the model taken to be wrong (gate_reset_after rejections in a row)
  /// Steps whose winding reading was refused as a held value (thermal_held_reading.hpp): frozen (eq. 14.28), or
  /// beyond the gate gate_reset_after times and more without moving; and whether the newest step's was.
  std::int64_t winding_readings_held = 0;
  bool winding_reading_held = false;
  [[nodiscard]] const ThermalNodeEstimate& magnet_node() const noexcept { return node[static_cast<std::size_t>(magnet)]; }
  [[nodiscard]] const ThermalNodeEstimate& winding_node() const noexcept { return node[static_cast<std::size_t>(winding)]; }
};

/// Where a reported node temperature comes from. The values are what RPEM_ESTIMATE's t_*_source and the estimate
/// log's *_source columns carry (rpem_estimate_t.lcm's SOURCE_* constants, which the daemon asserts agree).
enum class ThermalSource : std::int8_t {
  none = 0,       ///< the filter has not stepped
  observed = 1,   ///< corrected in the filter's newest step
  predicted = 2,  ///< not corrected in it
};

/// What RPEM_ESTIMATE and `rpem estimate --thermal` report of a node at `t_ns` (the newest sample, at or after
/// the filter's newest step): where it comes from; the age of the last observation run on to t_ns, −1: never
/// observed; NaN values before the first step.
struct ThermalNodeReport {
  double t_C = 0.0;
  double sd_K = 0.0;
  ThermalSource source = ThermalSource::none;
  double observed_age_s = -1.0;
};
[[nodiscard]] ThermalNodeReport report_node(const ThermalEstimate& e, int node, std::int64_t t_ns) noexcept;

/// The winding's temperature as a linear function of the filter's state [T; d; c]: T_w = row·[T; d; c] + constant_K.
/// The winding node itself, or with `winding_node_is_reading` the node led by τ_s times its modelled rate, the
/// coolant's error included (eq. 14.24, 14.29a).
struct WindingReadout {
  ThermalStateVec row = ThermalStateVec::Zero();
  double constant_K = 0.0;
};
/// `rates`: the network's at the step's load (thermal_rates).
[[nodiscard]] WindingReadout winding_readout(const ThermalFusionConfig& c, const ThermalRates& rates) noexcept;

/// The observations of one step as the filter takes them, from a step's data and the state they linearise at.
struct StepObservations {
  std::array<ThermalObservation, 3> item{};  ///< magnet (ψ̂m), winding (r̂s), winding sensor
  std::array<bool, 3> present{};
};
/// `rates`: the network's at the step's load (thermal_rates(network, s.load)); `lag`: the winding sensor's lag at
/// the step's start (eq. 14.22; unused when the sensor has none).
[[nodiscard]] StepObservations step_observations(const ThermalFusionConfig& c, const ThermalStepData& s,
                                                 const ThermalRates& rates, const ThermalVec& t_C,
                                                 const ThermalVec& dt_dt_K_per_s,
                                                 const SensorLag& lag = SensorLag{}) noexcept;
/// The same with the rates formed here.
[[nodiscard]] inline StepObservations step_observations(const ThermalFusionConfig& c, const ThermalStepData& s,
                                                        const ThermalVec& t_C, const ThermalVec& dt_dt_K_per_s,
                                                        const SensorLag& lag = SensorLag{}) noexcept {
  return step_observations(c, s, thermal_rates(c.filter.network, s.load), t_C, dt_dt_K_per_s, lag);
}

class ThermalFusion {
 public:
  ThermalFusion(const ThermalFusionConfig& config, const PerUnitBase& base, const MachineSi& machine) noexcept;

  /// One estimator sample. Real-time safe.
  void step(const Estimate& e, const ThermalSample& s) noexcept;
  /// One completed step of the observer (what step() does when the observer completes one): the first
  /// starts the filter, then predict and observe. Public for replays of recorded steps. Real-time safe.
  void apply(const ThermalStepData& d) noexcept;
  /// Advances the filter by `dt_s` under the last load without observations (no samples arrive).
  void coast(double dt_s) noexcept;
  /// The estimator was reset or given new values: observations wait until it settles again.
  void restart_observations() noexcept { observer_.restart(); }
  /// The newest sample's adaptation was taken back outside step() (a resynchronize() that retracted: rpemd's stale and
  /// implausible paths); ThermalObserver::retract_last. Real-time safe.
  void retract_last() noexcept { observer_.retract_last(); }
  /// The filter's state for a restart (rpemd's state file); nodes 0 before the first step. Real-time safe.
  [[nodiscard]] ThermalSnapshot snapshot() const noexcept;
  /// The first step starts from a state saved `gap_s` ago (across_unknown_load, in observer steps) instead of
  /// the coolant; false, and nothing changes, where the snapshot is not of this network. Before the loop runs.
  bool resume(const ThermalSnapshot& saved, double gap_s) noexcept;
  /// A reload: new model, laws and observer settings; the temperatures and their covariance are kept.
  void reconfigure(const ThermalFusionConfig& config, const PerUnitBase& base, const MachineSi& machine) noexcept;

  [[nodiscard]] const ThermalEstimate& estimate() const noexcept { return out_; }
  /// The newest step's observations (magnet from ψ̂m, winding from r̂s, winding sensor).
  struct ObservationReport {
    bool present = false;
    ObservationResult result = ObservationResult::kRejectedInvalid;
    double innovation = 0.0;  ///< ν, in the observation's unit
    double variance = 0.0;    ///< s = h·P·hᵀ + r
  };
  [[nodiscard]] const std::array<ObservationReport, 3>& last_observations() const noexcept { return reports_; }
  [[nodiscard]] const ThermalFilter& filter() const noexcept { return filter_; }
  [[nodiscard]] const ThermalFusionConfig& config() const noexcept { return config_; }

 private:
  void start(const ThermalStepData& s) noexcept;
  /// `rates`: the network's at d.load, as the prediction took them.
  void finish_step(const ThermalStepData& d, const ThermalRates& rates, double dt_s) noexcept;
  /// The step's observations at the filter's current state.
  [[nodiscard]] StepObservations observations_now(const ThermalStepData& d, const ThermalRates& rates) const noexcept;
  /// The held-reading check of the step's winding reading (eq. 14.28): withdraws the filter where it fires, and then
  /// forms `obs` again at the withdrawn state.
  ReadingMotion check_held_reading(const ThermalStepData& d, const ThermalRates& rates, StepObservations& obs) noexcept;
  /// Applies observation `k` of the step (of `node`): a held reading refused, the gate's refusals and resets; the
  /// report and the counters of held readings and resets. What the filter made of it.
  ObservationResult apply_observation(std::size_t k, const ThermalObservation& o, int node, ReadingMotion motion) noexcept;
  static constexpr std::size_t kSensorObservation = 2;  ///< StepObservations' order: magnet, winding from r̂s, sensor

  ThermalFusionConfig config_;
  ThermalObserver observer_;
  ThermalFilter filter_;
  ThermalEstimate out_;
  ThermalLoad last_load_;
  std::array<double, kMaxThermalNodes> since_observed_s_{};
  std::array<bool, kMaxThermalNodes> ever_observed_{};
  std::array<ObservationReport, 3> reports_{};
  std::array<int, 3> rejected_in_a_row_{};
  SensorLag sensor_lag_;                  ///< the winding sensor's lag at the next step's start (eq. 14.22)
  HeldReadingCheck held_reading_;         ///< the winding sensor's (eq. 14.28)
  bool sensor_moved_in_run_ = false;      ///< the winding readings of the current run of gate refusals are not one value
  bool sensor_taken_since_move_ = false;  ///< a winding reading was applied since the value last moved
  bool first_step_ = false;               ///< the step after start(): its reading may have set the start
  ThermalVec start_without_reading_C_ = ThermalVec::Zero();  ///< where start() would have put the nodes without it
  double last_psi_m_Wb_ = 0.0, last_r_s_Ohm_ = 0.0;
  ThermalSnapshot resumed_;  ///< where the first step starts (resume); nodes 0: from the coolant
};

/// The loss base of a machine: rated electrical speed, its ψm and rated peak current (per_unit.hpp's base).
[[nodiscard]] LossBase loss_base_of(const PerUnitBase& base, const MachineSi& machine) noexcept;

}  // namespace rpem::core
