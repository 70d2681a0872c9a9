#pragma once
// A winding sensor that lags the winding node (docs/derivations.md §14, eq. 14.22): a first-order element of
// time constant τ_s, dT_s/dt = (T_w − T_s)/τ_s, its readings averaged over the filter's step. With the lag
// e = T_w − T_s and the winding's rate s = dT_w/dt held over a step Δt (the zero-order hold of eq. 14.4),
// and the readings ā old on average at the step's end (variance v; thermal_observer.hpp, ReadingAge),
//
//   e⁺ = φ·e + τ_s·(1 − φ)·s,   φ = e^{−Δt/τ_s}
//   mean reading = T_w⁺ − κ·s − β·e,   κ = ā + τ_s·(1 − β),
//   β = mean of e^{−(Δt − age)/τ_s} = e^{−(Δt − ā)/τ_s}·sinh(x)/x,  x = √(3v)/τ_s         (eq. 14.22, 14.22a)
//
// exact for a rate held over the step; e the lag at the step's start. β is exact for the readings' ages spread
// evenly (a continuous mean, ā = Δt/2, v = Δt²/12: β = τ_s·(1 − φ)/Δt) and for one reading (v = 0: β = φ^(1 − ā/Δt)).
// The filter and `rpem thermal fit` both predict the sensor with these (one model). τ_s = 0: the reading is
// the node (no lag, no age term).
// Real-time safe: noexcept, no allocation.

#include "rpem/core/thermal_filter.hpp"
#include "rpem/core/thermal_observer.hpp"

namespace rpem::core {

/// The winding's rate s = dT_w/dt = A_w·T + d_w/C_w + u_w + (G_w0/C_w)·e_c as a row over the filter's whole state
/// [T; d; c] and its constant (eq. 14.22, 14.29a): what the lagging sensor's observation takes (h, h_d, h_c) and
/// its lag advances by. Of the calibration states only the coolant's error e_c moves the rate.
struct WindingRate {
  ThermalStateVec row = ThermalStateVec::Zero();
  double constant_K_per_s = 0.0;
};
[[nodiscard]] WindingRate winding_rate(const ThermalNetwork& n, const ThermalRates& rates) noexcept;

/// The coefficients of eq. 14.22 for one step.
struct SensorLagStep {
  double carry = 0.0;   ///< β [1]: the weight of the lag at the step's start in the step's mean reading
  double rate_s = 0.0;  ///< κ [s]: the weight of the step's rate
  double decay = 0.0;   ///< φ [1]
  double gain_s = 0.0;  ///< τ_s·(1 − φ) [s]
};
/// `age`: when the step's readings were taken (carry and rate_s; decay and gain_s do not depend on it).
[[nodiscard]] SensorLagStep sensor_lag_step(double time_constant_s, double dt_s, const ReadingAge& age) noexcept;

/// The sensor's lag e = T_w − T_s [K] at a step's start and its variance (the rates it was built from are
/// estimates).
struct SensorLag {
  double lag_K = 0.0;
  double variance_K2 = 0.0;
  /// Advances over the step by the winding's rate and that rate's variance (eq. 14.22; the variance fully
  /// correlated from step to step: σ_e⁺ = φ·σ_e + τ_s·(1 − φ)·σ_s, bounded by τ_s·σ_s at a steady σ_s).
  void advance(const SensorLagStep& k, double rate_K_per_s, double rate_variance_K2_per_s2) noexcept;
};

}  // namespace rpem::core
