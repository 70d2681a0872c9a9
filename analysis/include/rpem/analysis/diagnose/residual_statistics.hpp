#pragma once
// What the nominal model gets wrong, and what the extended model still gets wrong, summarised for a
// person (docs/diagnose.md, "Reading the report"): residual RMS and mean per operating region (speed ×
// load, standstill and motion), the residual's content at harmonics of the electrical angle (a sensor
// offset shows at the 1st in dq, a gain error at the 2nd, dead time at the 6th), the mean phase
// residual by the sign of that phase's current (the dead-time signature), and correlations with
// candidate regressors.

#include <string>
#include <vector>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/analysis/diagnose/replay.hpp"

namespace rpem::analysis {

/// A statistic of the nominal model's residual ("before") and the extended model's ("after").
struct BeforeAfter {
  double before = 0.0;
  double after = 0.0;
};

struct RegionStatistics {
  std::string speed;     ///< e.g. "standstill", "+0.02…0.5 pu"
  std::string load;      ///< "no load", "i_q > 0", "i_q < 0"
  std::size_t samples = 0;
  BeforeAfter rms_A;
  BeforeAfter mean_d_A, mean_q_A;
};

struct HarmonicContent {
  int order = 0;         ///< multiple of the electrical angle; 0 is the mean
  BeforeAfter amplitude_A;
};

struct PhaseSignStatistics {
  char phase = 'a';
  BeforeAfter mean_when_positive_A;  ///< mean residual of this phase while its current is positive
  BeforeAfter mean_when_negative_A;
};

struct RegressorCorrelation {
  std::string regressor;
  BeforeAfter d, q;      ///< Pearson correlation with the d and q residual
};

struct ResidualStatistics {
  BeforeAfter rms_A;                          ///< all used samples
  BeforeAfter standstill_rms_A, motion_rms_A;
  std::size_t standstill_samples = 0, motion_samples = 0;
  std::vector<RegionStatistics> regions;      ///< regions holding at least 0.5 % of the samples
  std::vector<HarmonicContent> harmonics;     ///< samples in motion; empty for steady-state logs
  std::vector<PhaseSignStatistics> phase_signs;
  std::vector<RegressorCorrelation> correlations;
};

[[nodiscard]] ResidualStatistics residual_statistics(const LogData& log, const EffectContext& context,
                                                     const ReplayOutput& nominal, const ReplayOutput& extended);

/// Speed below which a sample counts as standstill [pu of the rated speed].
inline constexpr double kStandstillSpeedPu = 0.02;

}  // namespace rpem::analysis
