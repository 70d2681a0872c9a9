#pragma once
// The averaged-sample estimator's options (`estimator.averaged`, docs/configuration.md): its gains as
// rates per second, the longest interval it adapts across, the inductive correction and the correction
// of per-cycle current samples to cycle means (docs/derivations.md §11).

#include <array>

#include "rpem/core/gain.hpp"

namespace rpem::core {

struct AveragedSettings {
  /// Gain sequences as rates [1/s], per algorithm, where `rates_given` says so; otherwise the
  /// estimator takes γ_0/sample_period_s of the native `gains` (the same time constants).
  std::array<GainSequences, 3> rates_per_s{};
  std::array<bool, 3> rates_given{};
  /// A sample more than this after the previous one adapts nothing (the stream was interrupted).
  double max_interval_s = 0.05;
  /// Subtract L·di/dt estimated from consecutive window means (§11); off: the plain steady state.
  bool inductive_correction = true;
  /// Time constant of the instrument: Ψᵀ is evaluated at the preceding samples' low-passed current and
  /// speed, whose noise is independent of the sample's own (§11: a same-sample regressor is biased in
  /// closed loop, more so the faster the samples come).
  double instrument_time_constant_s = 0.05;
  /// The drive's control period T_c [s] (one current sample and one held voltage per cycle): its means of
  /// per-cycle current samples are turned into means of the current (§11, "Sampled means"); 0: not done.
  double control_period_s = 0.0;
  /// Where in the interval over which the drive holds a voltage it samples the current, as a fraction of
  /// T_c: 0 at the instant the voltage takes effect (a PWM update at the sampling instant), 0.5 in its middle.
  double current_sample_at = 0.0;
  /// The drive reports the voltage it commands (computed in the frame of the current samples, taking effect
  /// `model_extensions.delay` later and held, fixed in the stator frame, for one period T_c), not the
  /// period's mean: the mean it applies is that command turned by a further −ω·T_c/2 and shortened by
  /// sinc(ω·T_c/2) (§11, "Reported command"). Needs control_period_s.
  bool voltage_is_command = false;
};

}  // namespace rpem::core
