#pragma once
// What the diagnosis takes from replays of the whole log (every block), streamed — nothing per sample kept:
//   the baseline's pass — the noise floor (verdict.hpp), the 0.1 s window where the configuration errs most
//     (the overlay figure's), the ranges the figures bin over;
//   the comparison's pass — the configuration and the extended model together: the residual statistics
//     (residual_statistics.hpp) and the figures' binned data (diagnose_figures.cpp).
// Each pass runs the blocks on the replay's pool and adds their sums in block order.

#include <array>
#include <cstddef>
#include <limits>
#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/replay.hpp"
#include "rpem/analysis/diagnose/residual_statistics.hpp"
#include "rpem/analysis/diagnose/verdict.hpp"

namespace rpem::analysis {

/// The figures' data (diagnose_figures.cpp draws them).
struct FigureData {
  /// Time bins: at most kTimeBins, of equal numbers of samples (every sample for short logs).
  static constexpr std::size_t kTimeBins = 1500;
  /// Per bin: t [s], speed [rpm], i_q [A], residual RMS before and after [A], mean ε_d and ε_q before [A],
  /// the drawn temperature [°C] (NaN where none).
  std::vector<std::array<double, 8>> time;

  /// The residual map over the operating plane (speed × i_q), kMapX × kMapY cells.
  static constexpr int kMapX = 40, kMapY = 30;
  double speed_lo_rpm = 0.0, speed_hi_rpm = 1.0, i_q_lo_A = 0.0, i_q_hi_A = 1.0;
  /// Per cell (row-major in i_q): Σ|ε|² before, after, and the count.
  std::vector<std::array<double, 3>> map;

  /// The mean residual against the drawn temperature (the winding's if logged), kTemperatureBins bins.
  static constexpr int kTemperatureBins = 60;
  double temperature_lo_C = 0.0, temperature_hi_C = 0.0;
  /// Per bin: count, Σε_d before, Σε_q before, Σε_d after, Σε_q after.
  std::vector<std::array<double, 5>> temperature;

  /// Samples in the overlay's window: t [s], logged i_d, i_q, the configuration's model i_d, i_q, the
  /// extended model's i_d, i_q [A].
  std::vector<std::array<double, 7>> overlay;
};

/// What the baseline's pass found.
struct BaselinePass {
  NoiseFloor noise_floor;  ///< of the baseline's residual (verdict.hpp)
  /// The overlay's window [first, last): transient logs the 0.1 s where the baseline errs most, steady
  /// state the whole log.
  std::size_t overlay_first = 0, overlay_last = 0;
  double speed_lo_rpm = std::numeric_limits<double>::infinity(), speed_hi_rpm = -std::numeric_limits<double>::infinity();
  double i_q_lo_A = std::numeric_limits<double>::infinity(), i_q_hi_A = -std::numeric_limits<double>::infinity();
  double temperature_lo_C = std::numeric_limits<double>::infinity(),
         temperature_hi_C = -std::numeric_limits<double>::infinity();
};

/// The baseline over the whole log.
[[nodiscard]] BaselinePass baseline_pass(const ModelReplay& replay, const EffectContext& context,
                                         const ExtendedModel& baseline);

/// The configuration (`baseline`) and the extended model over the whole log: the residual statistics and the
/// figures' data.
void comparison_pass(const ModelReplay& replay, const EffectContext& context, const ExtendedModel& baseline,
                     const ExtendedModel& extended, const BaselinePass& pass, ResidualStatistics& statistics,
                     FigureData& figures);

/// The electrical speed in rpm of the machine's rotor.
[[nodiscard]] double speed_rpm(const EffectContext& context, double omega_el_rad_s);

}  // namespace rpem::analysis
