#pragma once
// The estimator for averaged rotor-frame samples (VESC, signal maps, averaged drive logs; docs/sources.md):
// SI averaged samples in, SI and pu estimates out, beside DriveEstimator (which takes phase samples at the
// control rate). Each sample is predicted with the steady-state model of its window (docs/derivations.md
// §11), the inductive term estimated from consecutive window means; the gains, eq:GainSchedule and the
// projection are RpemEstimator's, its gain sequences applied as rates per second.
//
//   u_eff = ū − (x/ω_n)·(ī_k − ī_{k−1})/(c_k − c_{k−1})     c: window centres (inductive correction)
//   î = M̂⁻¹·(u_eff − [0, n̄·ψ̂m]ᵀ),  ε = ī − î                 (§1, eq_epsilon_steadystate)
//   Ψᵀ at the instrument: the current and speed of the preceding samples, low-passed
//
// Input corrections from model_extensions act as on the steady state of SampleConditioner (angle offset,
// dead time as its fundamental, saturation, iron loss) plus the command delay as a rotation by −ω·delay.
// Per-phase current offsets and gains have no rotor-frame mean and are left out (the tools refuse them).

#include <array>
#include <cstdint>
#include <optional>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/regime.hpp"

namespace rpem::core {

class AveragedDriveEstimator {
 public:
  using Sample = AveragedSample;

  AveragedDriveEstimator(const MachineSi& machine, const EstimatorSettings& settings) noexcept;

  /// One averaged sample. Real-time safe.
  [[nodiscard]] Estimate step(const AveragedSample& sample) noexcept;

  /// θ̂ and the Hessians back to their initial values; the next sample starts a new chain.
  void reset() noexcept;
  /// The next sample starts a new chain (adapts nothing); the chain it breaks ends (end_chain(), whose result it
  /// returns).
  bool resynchronize() noexcept {
    const bool retracted = end_chain();
    has_previous_ = false;
    classifier_.break_chain();
    return retracted;
  }
  /// The chain ends (the log's end, a gap, a stream broken off): its newest window is never judged, since a
  /// release inside it shows only in the window after it (docs/derivations.md §13, "Mixed windows"), so what
  /// it adapted is retracted. A sample that does not continue the chain ends it the same way. Returns whether
  /// a window's adaptation was taken back (not frozen, and the window was admitted): its step flags no longer
  /// hold (Estimate::retracted_previous). Real-time safe.
  bool end_chain() noexcept;
  /// Windows that ended a chain and were retracted by end_chain() (θ̂ moved back), since construction.
  [[nodiscard]] std::uint64_t unjudged_windows() const noexcept { return unjudged_windows_; }
  void set_frozen(bool frozen) noexcept { core_.set_frozen(frozen); }
  void set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept;
  /// Reloads gains, limits and model extensions, keeping θ̂ and the Hessians. Not real-time.
  void reconfigure(const MachineSi& machine, const EstimatorSettings& settings) noexcept;

  [[nodiscard]] const PerUnitBase& base() const noexcept { return base_; }
  [[nodiscard]] const RpemEstimator& core() const noexcept { return core_; }
  [[nodiscard]] const RegimeClassifier& classifier() const noexcept { return classifier_; }
  [[nodiscard]] double psi_m_Wb() const noexcept;
  [[nodiscard]] double r_s_Ohm() const noexcept;
  /// The time of the newest sample stepped, whatever became of it (rejected, or the first of a new
  /// chain), kept across reset() and resynchronize(); none before the first. rpemd's loop measures the
  /// time each sample stands for from it.
  [[nodiscard]] std::optional<std::int64_t> previous_t_ns() const noexcept { return previous_t_ns_; }

 private:
  /// The sample as the steady-state model takes it (pu, corrections applied, before the inductive
  /// correction), and how it continues the chain of the previous one (timing_).
  [[nodiscard]] SteadyStateSample condition(const AveragedSample& a) noexcept;
  void configure(const EstimatorSettings& settings) noexcept;
  /// The estimate of a stepped sample (and the count of its observation, where an instantaneous one adapted).
  [[nodiscard]] Estimate finish(const AveragedSample& sample, const SteadyStateSample& s, const EstimatorOutput& detail,
                                Classification regime, bool point, const GainSequences& gains) noexcept;

  PerUnitBase base_;
  SampleConditioner conditioner_;
  RpemEstimator core_;
  RegimeClassifier classifier_;
  PointGains point_gains_;  ///< the gains of instantaneous samples (one observation each)
  std::array<GainSequences, 3> rates_per_s_{};
  AveragedSettings options_;
  bool options_classify_ = true;  ///< estimator.regimes.enabled
  // Without classification the inductive correction's slope is taken here (the classifier takes it otherwise).
  std::int64_t previous_centre2_ns_ = 0;  ///< t_start + t of the previous window (twice its centre)
  Vec2 previous_i_pu_ = Vec2::Zero();
  double delay_s_ = 0.0;
  double staircase_below_rad_s_ = 0.0;  ///< estimator.regimes.hall_interpolation_speed_rad_s (window_speed_rad_s)
  bool has_previous_ = false;           ///< the next sample continues the chain of the previous one
  std::optional<std::int64_t> previous_t_ns_;
  SampleTiming timing_ = SampleTiming::kFirst;  ///< of the sample being stepped
  /// The core's adaptation before the previous sample: what a release found inside that window retracts (§13).
  RpemEstimator::Adaptation before_previous_{};
  /// The previous sample is a window that adapted in a chain and awaits its successor's release test.
  bool judge_pending_ = false;
  std::uint64_t unjudged_windows_ = 0;
  Vec2 instrument_i_pu_ = Vec2::Zero();  ///< low-passed current of the samples before this one
  double instrument_n_pu_ = 0.0;
};

}  // namespace rpem::core
