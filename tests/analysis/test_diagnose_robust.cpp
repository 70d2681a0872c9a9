// The rules `rpem diagnose` uses where real logs are not its emulators' (docs/diagnose.md, "Outliers and the
// robust loss", "Calibrated despite a large mismatch", "Noise floor and verdict"), against exact answers and
// seeded Gaussian samples: the outlier test's level and false rate, Huber's loss, the calibration's rule,
// and the noise floor's minimum count and its absence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/diagnose/robust_loss.hpp"
#include "rpem/analysis/diagnose/verdict.hpp"
#include "support/paper_machine.hpp"

namespace rpem::analysis {
namespace {

std::vector<double> gaussian_residuals(std::size_t n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> r(2 * n);
  for (double& v : r) v = noise(rng);
  return r;
}

TEST(OutlierTest, AGaussianBulkHasNoneAndAHeavyTailIsFound) {
  // N two-component Gaussian residuals (σ = 0.1 A per axis): the scale from the median is σ's, b is
  // σ·√(2 ln N), and at p ≤ 1e-3 no seed of twenty calls its tail heavy (P(any) ≈ 2 %).
  constexpr std::size_t n = 4000;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const OutlierTest t = test_outliers(gaussian_residuals(n, 0.1, seed));
    EXPECT_NEAR(t.scale_A, 0.1, 0.006) << seed;  // the median of χ²₂ from 4000: ±3 % (2σ) on σ
    EXPECT_NEAR(t.threshold_A, t.scale_A * std::sqrt(2.0 * std::log(static_cast<double>(n))), 1e-12);
    EXPECT_FALSE(t.outliers) << seed << ": " << t.beyond << " beyond, p = " << t.p_value;
  }
  // One sample in a hundred 20 σ away (a row the model cannot represent): found, and the bulk's scale barely
  // moves (the median of 1 % contamination: the 50.5th percentile, +0.7 % on σ).
  std::vector<double> r = gaussian_residuals(n, 0.1, 7);
  for (std::size_t k = 0; k < n; k += 100) r[2 * k] = 2.0;
  const OutlierTest t = test_outliers(r);
  EXPECT_TRUE(t.outliers);
  EXPECT_GE(t.beyond, n / 100);
  EXPECT_LT(t.p_value, 1e-20);
  EXPECT_NEAR(t.scale_A, 0.1, 0.007);
}

TEST(RobustLoss, HuberSquaresWithinTheThresholdAndIsLinearBeyond) {
  const RobustLoss least_squares;
  EXPECT_FALSE(least_squares.robust());
  EXPECT_EQ(least_squares.rho(123.0), 123.0);
  EXPECT_EQ(least_squares.residual_scale(123.0), 1.0);
  const RobustLoss huber{2.0};
  EXPECT_DOUBLE_EQ(huber.rho(1.0), 1.0);
  EXPECT_DOUBLE_EQ(huber.rho(4.0), 4.0);
  EXPECT_DOUBLE_EQ(huber.rho(16.0), 2.0 * 2.0 * 4.0 - 4.0);  // 2·b·|r| − b² at |r| = 4
  EXPECT_EQ(huber.residual_scale(3.9), 1.0);                 // within b exactly as least squares
  const double s = huber.residual_scale(16.0);
  EXPECT_DOUBLE_EQ(s * s * 16.0, huber.rho(16.0));  // the scaled residual's square is ρ
}

TEST(Calibration, AConstantIsKeptNarrowOrWhereTheLogRejectsTheConfiguration) {
  EffectSet set;
  CalibrationIntervals ci;
  set.calibration[0] = 3.0;  // +3 % (scaled: 1 = 1 %)
  ci.half_width[0] = 0.05;
  ci.change_per_A[0] = 0.01;  // 1 % per A of misfit norm
  EXPECT_EQ(identification(set, ci, 0, 0.0), Identification::kNarrow);
  EXPECT_TRUE(identified(set, ci, 0));
  // Wider than ±10 %: kept only where the configured value lies outside θ̂·(1 ± (h + m)).
  ci.half_width[0] = 0.2;
  set.calibration[0] = -20.0;  // θ̂ = 0.8·θ_c: |θ̂ − θ_c| = 0.2·θ_c against (h + m)·θ̂
  EXPECT_EQ(identification(set, ci, 0, 0.0), Identification::kRejectsConfiguration);  // 0.2 > 0.2·0.8
  EXPECT_EQ(identification(set, ci, 0, 5.0), Identification::kNot);                   // 0.2 < 0.25·0.8
  set.calibration[0] = -30.0;
  EXPECT_EQ(identification(set, ci, 0, 5.0), Identification::kRejectsConfiguration);  // 0.3 > 0.25·0.7
  EXPECT_FALSE(identified(set, ci, 0));  // the effects' tests keep the narrow rule
  // At the ±50 % bound nothing is kept, however narrow.
  set.calibration[0] = -49.8;
  ci.half_width[0] = 0.01;
  EXPECT_EQ(identification(set, ci, 0, 0.0), Identification::kNot);
  // The misfit above the floor, as a norm over the training samples.
  EXPECT_DOUBLE_EQ(misfit_norm_A(100, 0.5, 0.3), std::sqrt(100.0 * (0.25 - 0.09)));
  EXPECT_EQ(misfit_norm_A(100, 0.2, 0.3), 0.0);
  EXPECT_DOUBLE_EQ(misfit_norm_A(100, 0.5, 0.0), 5.0);  // floor unknown: all of it
}

/// A log of `n` rows in one block whose replay is `n` valid white residuals.
std::pair<LogData, ReplayOutput> white_run(std::size_t n, std::mt19937_64& rng) {
  LogData log;
  log.samples = SampleStore(io::DriveLogLayout{});
  for (std::size_t k = 0; k < n; ++k) {
    io::DriveLogRow row;
    row.sample.t_ns = static_cast<std::int64_t>(k) * 125'000;
    log.samples.push_back(row);
  }
  log.samples.finish();
  log.blocks = 1;
  log.block_first = {0, n};
  ReplayOutput r;
  r.valid.assign(n, true);
  r.residual_A.resize(n);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (auto& v : r.residual_A) v = core::Vec2(noise(rng), noise(rng));
  return {std::move(log), std::move(r)};
}

/// The 2.5 % quantile of the floor's estimate from `differences` second differences, relative to the truth.
double low_quantile(std::size_t differences) {
  std::mt19937_64 rng(23);
  std::vector<double> ratio;
  for (int trial = 0; trial < 4000; ++trial) {
    const auto [log, r] = white_run(differences + 2, rng);
    const NoiseFloor f = measure_noise_floor(log, r);
    if (f.value_A) ratio.push_back(*f.value_A / std::sqrt(2.0));
  }
  if (ratio.size() != 4000U) {
    ADD_FAILURE() << "measured in " << ratio.size() << " of 4000 trials";
    return 0.0;
  }
  std::sort(ratio.begin(), ratio.end());
  return ratio[ratio.size() / 40];
}

TEST(NoiseFloor, TwentySecondDifferencesMeasureItWellEnoughForTheVerdict) {
  // From kMinNoiseDifferences = 20 second differences the estimate's 2.5 % quantile lies at ≥ 1/1.5 of the
  // true floor, so a residual that is the noise is called explained (≤ 1.5 × the floor) 97.5 % of the
  // time (from 10, the count diagnose accepted before, it lay at 0.59).
  EXPECT_GE(low_quantile(kMinNoiseDifferences), 1.0 / kExplainedRatio - 0.01);
  std::mt19937_64 rng(5);
  const auto [log, r] = white_run(kMinNoiseDifferences + 1, rng);  // one difference short
  const NoiseFloor f = measure_noise_floor(log, r);
  EXPECT_FALSE(f.value_A);
  EXPECT_EQ(f.differences, kMinNoiseDifferences - 1);
}

TEST(NoiseFloor, UnknownWhereNoRowsRepeatAnOperatingPointAndTheVerdictIsUndetermined) {
  // A bench's sparse rows of a dynamic profile: the operating point changes every third row (7.5 s), so every
  // row but the middle of each run is in transition and no three consecutive rows are replayed.
  std::vector<io::DriveLogRow> rows;
  for (int k = 0; k < 240; ++k) {
    io::DriveLogRow row;
    row.sample.t_ns = static_cast<std::int64_t>(k) * 2'500'000'000LL;
    row.sample.voltage_frame = row.sample.current_frame = core::Frame::kDq;
    const bool high = (k / 3) % 2 == 0;
    row.sample.omega_el_rad_s = high ? 300.0 : 150.0;
    row.sample.i_A = high ? core::Vec3(-3.0, 4.0, 0.0) : core::Vec3(-1.0, 1.5, 0.0);
    row.sample.u_V = core::Vec3(10.0, high ? 200.0 : 100.0, 0.0);
    rows.push_back(row);
  }
  const LogData log = prepare_log(std::move(rows), io::DriveLogLayout{}, test::paper_machine_si(), {});
  ASSERT_EQ(log.mode, ModelMode::kSteadyState);
  ReplayOutput r;
  r.valid.resize(log.size());
  for (std::size_t k = 0; k < log.size(); ++k) r.valid[k] = log.used(k);
  r.residual_A.assign(log.size(), core::Vec2(0.1, -0.1));
  const NoiseFloor f = measure_noise_floor(log, r);
  ASSERT_FALSE(f.value_A);
  EXPECT_EQ(f.differences, 0U);
  EXPECT_NE(f.unknown_reason.find("in transition between operating points"), std::string::npos) << f.unknown_reason;
  EXPECT_EQ(f.for_fits_A(), 0.0);

  ResidualStatistics st;
  st.motion_samples = 80;
  st.motion_rms_A = {1.0, 0.14};
  const Verdict v = verdict(0.14, f, st);
  EXPECT_EQ(v.kind, VerdictKind::kUndetermined);
  EXPECT_STREQ(to_string(v.kind), "undetermined");
  EXPECT_FALSE(v.noise_floor_A);
  EXPECT_FALSE(v.ratio);
  ASSERT_GE(v.findings.size(), 3U);
  EXPECT_NE(v.findings[0].find("cannot be measured"), std::string::npos) << v.findings[0];
  std::string all;
  for (const std::string& s : v.findings) all += s + "\n";
  EXPECT_EQ(all.find("inf"), std::string::npos) << all;
  EXPECT_EQ(all.find("at standstill 0 A"), std::string::npos) << all;
  EXPECT_NE(all.find("no samples at standstill"), std::string::npos) << all;
}

}  // namespace
}  // namespace rpem::analysis
