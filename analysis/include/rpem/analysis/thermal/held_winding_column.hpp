#pragma once
// A winding-sensor column that holds one value while r̂s says the winding moved (docs/derivations.md eq. 14.28b;
// docs/thermal.md, "A winding reading that holds one value"). rpem estimate's filter finds a held reading against its
// network (eq. 14.28); the fit has no network yet — it is what the column would be fitted to — so it judges the column
// against the one winding temperature that needs none: r̂s through the copper law, wherever r̂s adapts. Over a run of
// steps on one reading (core::same_reading; no reading leaves the run open), with T_k r̂s's winding at step k, σ_k its
// standard deviation (the observer's variance through the law), the run's first observation 0:
//
//   held ⇔ ρ·|T_k − T_0| > q + z·√(σ_k² + σ_0² + 2σ_s²)   for some k in the run                       (14.28b)
//
// ρ = α/α_max: the law's coefficient against its material's largest, so a move is never overstated by a law that
// is too steep; q the column's resolution (its smallest step between two readings; 1 K, the coarsest a drive reports,
// where it never moves); σ_s the sensor's own σ about the winding it reads, at each end; z the normal quantile at
// which the whole record's comparisons M give a false finding with probability at most kHeldColumnFalseRate
// (Bonferroni: 2·M·Φ(−z) ≤ kHeldColumnFalseRate). A live sensor moves by q once the winding it reads moves by q, so
// only a reading that no longer reads passes (14.28b). Readings the sensor's lag τ_s would still hold — within 5·τ_s
// of the step the reading next changes — are not compared. What it cannot see: a held value where r̂s never adapts
// (at speed, or without current). The fit's second look finds that one where the column is live elsewhere and the
// losses change while it holds (eq. 14.28c): the filter, run with the network fitted to the column, refuses a reading
// the network says the winding has moved away from (eq. 14.28); a run of one reading holding such a step is set aside
// as (14.28b) sets one, and the network fitted again without it.

#include <cstddef>
#include <string>
#include <vector>

#include "rpem/analysis/thermal/thermal_record.hpp"
#include "rpem/core/thermal.hpp"
#include "rpem/core/thermal_fusion.hpp"

namespace rpem::analysis {

/// The probability, over a whole record, that (14.28b) finds a live column held by the r̂s observations' noise.
inline constexpr double kHeldColumnFalseRate = 1e-3;
/// The resolution taken for a column that never changes: the coarsest a drive gives (J1939's 1 °C per bit).
inline constexpr double kCoarsestReadingResolution_K = 1.0;

/// One run of a held value: the readings of steps [first, end) set aside.
struct HeldWindingRun {
  enum class FoundBy {
    kRsObservations,  ///< eq. 14.28b: moved_K and allowed_K say why
    kFittedNetwork,   ///< eq. 14.28c: refused_steps say why
  };
  FoundBy found_by = FoundBy::kRsObservations;
  std::size_t first = 0, end = 0;
  double t_first_s = 0.0, t_last_s = 0.0;  ///< the record's times of its first and last step
  std::string log;                         ///< its session's log
  double value_C = 0.0;
  double moved_K = 0.0;           ///< ρ·|T_k − T_0| where (14.28b) holds by the widest margin
  double allowed_K = 0.0;         ///< its right-hand side there
  std::size_t refused_steps = 0;  ///< eq. 14.28c: the steps the fitted network's filter refused as held
  bool whole_session = false;     ///< every reading of its session
};

struct HeldWindingColumn {
  std::vector<HeldWindingRun> runs;
  double resolution_K = 0.0;  ///< q
  double z = 0.0;             ///< the quantile used
  /// One sentence per run for the tools' notes (empty: none); `column` names the sensor's column.
  [[nodiscard]] std::vector<std::string> describe(const std::string& column) const;
};

/// Finds (14.28b) in the record's winding-sensor column and sets those readings to NaN; a record whose every reading
/// is held is left without a winding sensor. `copper`: the winding's law; `sensor_sigma_K`: σ_s;
/// `sensor_time_constant_s`: τ_s (0: none known).
HeldWindingColumn drop_held_winding_readings(ThermalRecord& r, const core::DriftLaw& copper, double sensor_sigma_K,
                                             double sensor_time_constant_s);

/// The fit's second look (eq. 14.28c): the filter with `fitted` (the network fitted to the column) over the whole
/// record; each run of one reading holding a step the filter refused as held (eq. 14.28) is set to NaN, as
/// drop_held_winding_readings does. Nothing found: the record is unchanged.
HeldWindingColumn drop_winding_readings_the_network_holds(ThermalRecord& r, const core::ThermalFusionConfig& fitted);

}  // namespace rpem::analysis
