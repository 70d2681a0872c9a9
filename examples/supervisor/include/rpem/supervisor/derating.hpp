#pragma once
// The derating law of the supervisory controller (docs/supervisor.md, "The derating law"). For each
// protected part c (the magnet, the winding) with a warning temperature W_c < a limit L_c and a floor
// current F_c, and the rated current I_r:
//
//     T⁺_c = T̂_c + 2·σ_c + Ṫ_max,c · a_c                  the temperature's upper bound
//
//                  ⎧ I_r                                 T⁺ ≤ W
//     I_c(T⁺)  =   ⎨ I_r − (I_r − F)·(T⁺ − W)/(L − W)      W < T⁺ ≤ L
//                  ⎩ 0                                   T⁺ > L
//
//     I_max    =   min(I_magnet, I_winding)
//
// with a_c the time the value has gone without being observed or predicted anew (a held RPEM value's
// age plus the message's own age), and σ_c the fused estimate's standard deviation or, for a raw
// RPEM-derived value, the configured one. A part whose temperature is unknown — no trustworthy estimate,
// not valid, not finite — is taken to be at its limit: I_c = F_c. F_c is the current that cannot harm
// the part at L_c (for the magnet: no irreversible demagnetisation at L_c, from the magnet grade's knee
// and the machine's design), so a drive without a temperature can still run at F_c — and move, so ψm
// can be identified — while above the limit it gets nothing.

#include <optional>

namespace rpem::supervisor {

/// A protected part's temperatures and the current it allows at its limit.
struct PartLimits {
  double warning_C = 0.0;     ///< W: full current up to here
  double limit_C = 0.0;       ///< L: the floor current here, nothing above (> warning_C)
  double floor_A = 0.0;       ///< F: in [0, rated_current_A]
  double raw_sd_K = 0.0;      ///< σ of a raw RPEM-derived temperature while valid (thermal model off)
  double max_rate_K_s = 0.0;  ///< Ṫ_max: the fastest the part can heat while its value is not renewed
};

/// What is known of a part's temperature at one moment: an estimate, its σ and how long it has gone
/// unrenewed — or nothing.
struct TemperatureEstimate {
  double t_C = 0.0;
  double sd_K = 0.0;
  double unrenewed_s = 0.0;  ///< a
};

/// T⁺ = T̂ + 2σ + Ṫ_max·a.
[[nodiscard]] double upper_bound_C(const PartLimits& part, const TemperatureEstimate& t) noexcept;

/// I_c(T⁺) by the law above; `t_upper_C` empty (unknown) gives the floor.
[[nodiscard]] double part_current_A(const PartLimits& part, double rated_current_A,
                                    std::optional<double> t_upper_C) noexcept;

}  // namespace rpem::supervisor
