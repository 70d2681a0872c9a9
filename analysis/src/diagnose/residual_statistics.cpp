#include "rpem/analysis/diagnose/residual_statistics.hpp"

#include <array>
#include <cmath>
#include <complex>
#include <functional>

#include "rpem/core/clock.hpp"
#include "rpem/core/conditioner.hpp"

namespace rpem::analysis {
namespace {

constexpr int kMaxHarmonic = 12;
/// |i_q| below this share of the base current counts as no load.
constexpr double kNoLoadShare = 0.05;
/// Regions with fewer than this share of the samples are left out of the table.
constexpr double kMinRegionShare = 0.005;

/// Sums for mean and RMS of a 2-vector.
struct Moments {
  std::size_t n = 0;
  core::Vec2 sum = core::Vec2::Zero();
  double sum_sq = 0.0;
  void add(const core::Vec2& v) {
    ++n;
    sum += v;
    sum_sq += v.squaredNorm();
  }
  [[nodiscard]] double rms() const { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }
  [[nodiscard]] core::Vec2 mean() const { return n ? core::Vec2(sum / static_cast<double>(n)) : core::Vec2::Zero(); }
};

/// Pearson correlation accumulated over pairs.
struct Pearson {
  double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  void add(double x, double y) {
    n += 1;
    sx += x;
    sy += y;
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  [[nodiscard]] double value() const {
    const double vx = n * sxx - sx * sx, vy = n * syy - sy * sy;
    return vx > 0.0 && vy > 0.0 ? (n * sxy - sx * sy) / std::sqrt(vx * vy) : 0.0;
  }
};

const char* const kSpeedRegions[] = {"n ≤ −0.5 pu", "−0.5 < n < 0 pu", "standstill", "0 < n < 0.5 pu", "n ≥ 0.5 pu"};
const char* const kLoadRegions[] = {"i_q < 0", "no load", "i_q > 0"};

/// Index into kSpeedRegions.
int speed_region(double n_pu) {
  if (std::abs(n_pu) < kStandstillSpeedPu) return 2;
  if (n_pu <= -0.5) return 0;
  if (n_pu < 0.0) return 1;
  return n_pu < 0.5 ? 3 : 4;
}

/// Index into kLoadRegions.
int load_region(double i_q_A, double base_current_A) {
  if (std::abs(i_q_A) < kNoLoadShare * base_current_A) return 1;
  return i_q_A > 0.0 ? 2 : 0;
}

/// The residuals' harmonics of the electrical angle (in motion) and their means by the sign of each phase
/// current: the transient mode's statistics.
struct TransientSums {
  std::array<std::array<std::complex<double>, 2>, kMaxHarmonic + 1> harm_before{}, harm_after{};
  std::size_t harmonic_samples = 0;
  std::array<Moments, 3> pos_before{}, pos_after{}, neg_before{}, neg_after{};

  void add(double theta_el_rad, bool still, const core::Vec2& i, const core::Vec2& rb, const core::Vec2& ra) {
    const core::Rotation rot = core::Rotation::of(theta_el_rad);
    if (!still) {
      ++harmonic_samples;
      for (int h = 0; h <= kMaxHarmonic; ++h) {
        const std::complex<double> e = std::polar(1.0, -h * theta_el_rad);
        harm_before[h][0] += rb[0] * e;
        harm_before[h][1] += rb[1] * e;
        harm_after[h][0] += ra[0] * e;
        harm_after[h][1] += ra[1] * e;
      }
    }
    const core::Vec3 i_abc = core::inverse_clarke(core::inverse_park(i, rot));
    const core::Vec3 r_abc_b = core::inverse_clarke(core::inverse_park(rb, rot));
    const core::Vec3 r_abc_a = core::inverse_clarke(core::inverse_park(ra, rot));
    for (int x = 0; x < 3; ++x) {
      (i_abc[x] > 0.0 ? pos_before : neg_before)[x].add({r_abc_b[x], 0.0});
      (i_abc[x] > 0.0 ? pos_after : neg_after)[x].add({r_abc_a[x], 0.0});
    }
  }

  void write(ResidualStatistics& out) const {
    if (harmonic_samples == 0) return;
    const double scale = 2.0 / static_cast<double>(harmonic_samples);
    for (int h = 0; h <= kMaxHarmonic; ++h) {
      // Amplitude of the residual vector's component at h·ϑ (the mean for h = 0).
      const double f = h == 0 ? 0.5 * scale : scale;
      const double before = f * std::hypot(std::abs(harm_before[h][0]), std::abs(harm_before[h][1]));
      const double after = f * std::hypot(std::abs(harm_after[h][0]), std::abs(harm_after[h][1]));
      out.harmonics.push_back({h, {before, after}});
    }
    for (int x = 0; x < 3; ++x) {
      out.phase_signs.push_back({static_cast<char>('a' + x), {pos_before[x].mean()[0], pos_after[x].mean()[0]},
                                 {neg_before[x].mean()[0], neg_after[x].mean()[0]}});
    }
  }
};

/// A quantity the residuals are correlated with.
struct Regressor {
  std::string name;
  std::function<double(std::size_t, const core::Vec2&, double)> value;  ///< sample, logged i_dq, n_pu
};

std::vector<Regressor> regressors_of(const LogData& log) {
  std::vector<Regressor> regressors = {
      {"|i| [A]", [](std::size_t, const core::Vec2& i, double) { return i.norm(); }},
      {"i_d [A]", [](std::size_t, const core::Vec2& i, double) { return i[0]; }},
      {"i_q [A]", [](std::size_t, const core::Vec2& i, double) { return i[1]; }},
      {"speed [pu]", [](std::size_t, const core::Vec2&, double n) { return n; }},
      {"|speed| [pu]", [](std::size_t, const core::Vec2&, double n) { return std::abs(n); }},
      {"time [s]", [&log](std::size_t k, const core::Vec2&, double) { return core::to_seconds(log.rows[k].sample.t_ns); }},
  };
  if (log.layout.t_winding) {
    regressors.push_back({"T_winding [°C]", [&log](std::size_t k, const core::Vec2&, double) { return log.rows[k].t_winding_C.value_or(0.0); }});
  }
  if (log.layout.t_magnet) {
    regressors.push_back({"T_magnet [°C]", [&log](std::size_t k, const core::Vec2&, double) { return log.rows[k].t_magnet_C.value_or(0.0); }});
  }
  return regressors;
}

}  // namespace

ResidualStatistics residual_statistics(const LogData& log, const EffectContext& context, const ReplayOutput& nominal,
                                       const ReplayOutput& extended) {
  const core::PerUnitBase base = core::PerUnitBase::from_rated(context.machine.rated);
  const core::SampleConditioner raw(base, core::to_pu(base, context.machine), {});
  const bool transient = log.mode == ModelMode::kTransient;

  std::array<std::array<Moments, 3>, 5> region_before{}, region_after{};
  Moments all_before, all_after, still_before, still_after, moving_before, moving_after;
  TransientSums transient_sums;
  const std::vector<Regressor> regressors = regressors_of(log);
  std::vector<std::array<Pearson, 4>> corr(regressors.size());  // d before, q before, d after, q after

  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (!nominal.valid[k] || !extended.valid[k]) continue;
    const core::DriveSample& s = log.rows[k].sample;
    const core::Vec2& rb = nominal.residual_A[k];
    const core::Vec2& ra = extended.residual_A[k];
    const core::Vec2 i = raw.logged_current_dq_A(s);
    const double n = s.omega_el_rad_s / base.omega_el_rad_s;
    all_before.add(rb);
    all_after.add(ra);
    const bool still = std::abs(n) < kStandstillSpeedPu;
    (still ? still_before : moving_before).add(rb);
    (still ? still_after : moving_after).add(ra);
    const int sr = speed_region(n), lr = load_region(i[1], base.current_A);
    region_before[sr][lr].add(rb);
    region_after[sr][lr].add(ra);

    if (transient) transient_sums.add(s.theta_el_rad, still, i, rb, ra);
    for (std::size_t j = 0; j < regressors.size(); ++j) {
      const double v = regressors[j].value(k, i, n);
      corr[j][0].add(v, rb[0]);
      corr[j][1].add(v, rb[1]);
      corr[j][2].add(v, ra[0]);
      corr[j][3].add(v, ra[1]);
    }
  }

  ResidualStatistics out;
  out.rms_A = {all_before.rms(), all_after.rms()};
  out.standstill_rms_A = {still_before.rms(), still_after.rms()};
  out.motion_rms_A = {moving_before.rms(), moving_after.rms()};
  out.standstill_samples = still_before.n;
  out.motion_samples = moving_before.n;
  for (int sr = 0; sr < 5; ++sr) {
    for (int lr = 0; lr < 3; ++lr) {
      const Moments& b = region_before[sr][lr];
      // Regions a log only passes through (a few samples in a transient) say little.
      if (static_cast<double>(b.n) < kMinRegionShare * static_cast<double>(all_before.n) || b.n == 0) continue;
      const Moments& a = region_after[sr][lr];
      out.regions.push_back({kSpeedRegions[sr], kLoadRegions[lr], b.n, {b.rms(), a.rms()}, {b.mean()[0], a.mean()[0]},
                             {b.mean()[1], a.mean()[1]}});
    }
  }
  transient_sums.write(out);
  for (std::size_t j = 0; j < regressors.size(); ++j) {
    out.correlations.push_back({regressors[j].name, {corr[j][0].value(), corr[j][2].value()},
                                {corr[j][1].value(), corr[j][3].value()}});
  }
  return out;
}

}  // namespace rpem::analysis
