#pragma once
// What the nominal model gets wrong, and what the extended model still gets wrong, summarised for a
// person (docs/diagnose.md, "Reading the report"): residual RMS and mean per operating region (speed ×
// load, standstill and motion), the residual's content at harmonics of the electrical angle (a sensor
// offset shows at the 1st in dq, a gain error at the 2nd, dead time at the 6th), the mean phase
// residual by the sign of that phase's current (the dead-time signature), and correlations with
// candidate regressors.

#include <array>
#include <complex>
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
  std::string speed;  ///< e.g. "standstill", "+0.02…0.5 pu"
  std::string load;   ///< "no load", "i_q > 0", "i_q < 0"
  std::size_t samples = 0;
  BeforeAfter rms_A;
  BeforeAfter mean_d_A, mean_q_A;
};

struct HarmonicContent {
  int order = 0;  ///< multiple of the electrical angle; 0 is the mean
  BeforeAfter amplitude_A;
};

struct PhaseSignStatistics {
  char phase = 'a';
  BeforeAfter mean_when_positive_A;  ///< mean residual of this phase while its current is positive
  BeforeAfter mean_when_negative_A;
};

struct RegressorCorrelation {
  std::string regressor;
  BeforeAfter d, q;  ///< Pearson correlation with the d and q residual
};

struct ResidualStatistics {
  BeforeAfter rms_A;  ///< all used samples
  BeforeAfter standstill_rms_A, motion_rms_A;
  std::size_t standstill_samples = 0, motion_samples = 0;
  std::vector<RegionStatistics> regions;   ///< regions holding at least 0.5 % of the samples
  std::vector<HarmonicContent> harmonics;  ///< samples in motion; empty for steady-state logs
  std::vector<PhaseSignStatistics> phase_signs;
  std::vector<RegressorCorrelation> correlations;
};

/// The sums behind ResidualStatistics, sample by sample, for replays that stream: each block adds its
/// samples to its own, and the blocks' are merged in block order.
class ResidualSums {
 public:
  ResidualSums(const LogData& log, const EffectContext& context);
  /// Sample k, where both the nominal and the extended model predict it.
  void add(std::size_t k, const core::Vec2& nominal_A, const core::Vec2& extended_A);
  void merge(const ResidualSums& other);
  [[nodiscard]] ResidualStatistics statistics() const;

 private:
  static constexpr int kMaxHarmonic = 12;
  /// Sums for mean and RMS of a 2-vector.
  struct Moments {
    std::size_t n = 0;
    core::Vec2 sum = core::Vec2::Zero();
    double sum_sq = 0.0;
    void add(const core::Vec2& v);
    void merge(const Moments& o);
    [[nodiscard]] double rms() const;
    [[nodiscard]] core::Vec2 mean() const;
  };
  /// Pearson correlation accumulated over pairs.
  struct Pearson {
    double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    void add(double x, double y);
    void merge(const Pearson& o);
    [[nodiscard]] double value() const;
  };
  /// The regressors' values at sample k (logged current, speed in pu).
  [[nodiscard]] double regressor(std::size_t j, std::size_t k, const core::Vec2& i, double n_pu) const;

  const LogData* log_;
  core::PerUnitBase base_;
  std::vector<std::string> regressors_;
  std::array<std::array<Moments, 3>, 5> region_before_{}, region_after_{};
  Moments all_before_, all_after_, still_before_, still_after_, moving_before_, moving_after_;
  std::array<std::array<std::complex<double>, 2>, kMaxHarmonic + 1> harm_before_{}, harm_after_{};
  std::size_t harmonic_samples_ = 0;
  std::array<Moments, 3> pos_before_{}, pos_after_{}, neg_before_{}, neg_after_{};
  std::vector<std::array<Pearson, 4>> corr_;  ///< d before, q before, d after, q after
};

/// The statistics of two whole replays (tests; a diagnosis streams into ResidualSums).
[[nodiscard]] ResidualStatistics residual_statistics(const LogData& log, const EffectContext& context,
                                                     const ReplayOutput& nominal, const ReplayOutput& extended);

/// Speed below which a sample counts as standstill [pu of the rated speed].
inline constexpr double kStandstillSpeedPu = 0.02;

}  // namespace rpem::analysis
