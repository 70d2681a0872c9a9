#pragma once
// A winding reading that holds one value (docs/derivations.md §14, eq. 14.28; docs/thermal.md, "A winding
// reading that holds one value"). A drive that sends a held value in place of a reading — a sensor input set to
// "disabled" that reports a constant, a field nobody updates, a sensor come loose into a stuck input — sends the
// same number whatever the winding does. Two things only such a value does:
//
// 1. It does not move while the network says it must. The gate cannot see this: the filter follows the value step
//    by step (each step's innovation is one step's change) and its heat disturbance learns to cancel the losses.
//    So an open-loop copy of the network runs beside the filter from the state the filter had at the step the
//    reading last changed (its temperatures and heat disturbances then; each step's noise-free transition since);
//    with h, h_d the reading's row in the filter's observation,
//
//      Δ = h·(T_open − T_change) + h_d·(d_open − d_change),   frozen ⇔ unchanged and Δ² > g²·s       (14.28)
//
//    g the filter's gate (gate_sigma), s the innovation variance it gates the reading by: the network predicts a
//    change of the reading that the filter itself would refuse as a disagreement. A live sensor moves by one
//    resolution step long before (0.1 K on a VESC, ≤ 1 K on any drive, far inside g·√s); a model biased by b at a
//    steady state moves the copy by about b, so a live reading resting on one value trips it only where the model
//    is off by about the gate.
// 2. Where it jumps to a wrong value and stays, the gate refuses it, and gate_reset_after refusals in a row would
//    take the model to be wrong and accept it. A run of refusals is evidence that the model drifted only where the
//    refused readings move; one held value is not (ThermalFusion: no reset while the run's readings are one value).
//
// "One value" is within kHeldReadingRelTolerance: far below any sensor's resolution, far above the rounding of a
// step's weighted mean of equal readings. Where (14.28) fires after the filter took the value, the filter is
// withdrawn to where it would be without it (ThermalFilter::withdraw_to: [T; d] moved there, the temperatures'
// covariance widened by their move, so the band covers both; eq. 14.28a): the copy, or, for a value held from the
// filter's start (which set the start: a machine read as not soaked), the start without it run open loop to now.
// The reading is refused (ObservationResult::kRejectedHeld, counted) until it changes, when the copy restarts.
// Real-time safe.

#include <algorithm>
#include <cmath>

#include "rpem/core/thermal_filter.hpp"

namespace rpem::core {

/// Two step means closer than this (relative to the larger, at least 1 K) are one value: 10⁻⁹ K at room
/// temperature, ~10⁶ times a mean's rounding and ~10⁸ times below a 0.1 K resolution.
inline constexpr double kHeldReadingRelTolerance = 1e-9;

/// Whether two readings are one value (kHeldReadingRelTolerance); a NaN is no value and never one.
[[nodiscard]] inline bool same_reading(double a, double b) noexcept {
  const double larger = std::max({1.0, std::abs(a), std::abs(b)});
  return std::abs(a - b) <= kHeldReadingRelTolerance * larger;
}

/// A step's reading against the one before it.
enum class ReadingMotion : std::uint8_t {
  kMoved = 0,      ///< a new value (or the first): the copy restarts here
  kSame = 1,       ///< the previous value, the network not (yet) against it
  kFrozenNow = 2,  ///< the previous value, and from this step the network says it must have moved (eq. 14.28)
  kFrozen = 3,     ///< still that value
};
[[nodiscard]] constexpr bool is_frozen(ReadingMotion m) noexcept {
  return m == ReadingMotion::kFrozenNow || m == ReadingMotion::kFrozen;
}

class HeldReadingCheck {
 public:
  /// Runs the open-loop copy over the step the filter has just predicted (every step, a reading or not).
  void advance(const ThermalFilter& f) noexcept;
  /// A step's reading: `o` is the observation the filter would take it by, at the filter's prior of this step.
  [[nodiscard]] ReadingMotion check(const ThermalFilter& f, const ThermalObservation& o) noexcept;
  /// Forgets the reading (a filter start).
  void restart() noexcept { running_ = false; }
  /// Where the filter would be now without the current value, where that is not the filter's state at the step the
  /// value came (a value held from the filter's start, which set the start: the start without it, run to now).
  void retarget(const ThermalVec& t_C, const ThermalVec& d_W) noexcept {
    target_t_C_ = t_C;
    target_d_W_ = d_W;
  }

  /// The withdrawal target: the network alone since the value came, from where the filter would have been without it.
  [[nodiscard]] const ThermalVec& target_temperature_C() const noexcept { return target_t_C_; }
  [[nodiscard]] const ThermalVec& target_disturbance_W() const noexcept { return target_d_W_; }

 private:
  bool running_ = false, frozen_ = false;
  double value_ = 0.0;
  ThermalVec t_at_change_C_ = ThermalVec::Zero(), d_at_change_W_ = ThermalVec::Zero();
  ThermalVec t_C_ = ThermalVec::Zero(), d_W_ = ThermalVec::Zero();  ///< the copy from the filter's state then
  ThermalVec target_t_C_ = ThermalVec::Zero(), target_d_W_ = ThermalVec::Zero();
};

}  // namespace rpem::core
