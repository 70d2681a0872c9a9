#include "rpem/analysis/diagnose/residual_statistics.hpp"

#include <cmath>

#include "rpem/core/clock.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/non_finite.hpp"

namespace rpem::analysis {
namespace {

/// |i_q| below this share of the base current counts as no load.
constexpr double kNoLoadShare = 0.05;
/// Regions with fewer than this share of the samples are left out of the table.
constexpr double kMinRegionShare = 0.005;

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

}  // namespace

void ResidualSums::Moments::add(const core::Vec2& v) {
  ++n;
  sum += v;
  sum_sq += v.squaredNorm();
}
void ResidualSums::Moments::merge(const Moments& o) {
  n += o.n;
  sum += o.sum;
  sum_sq += o.sum_sq;
}
double ResidualSums::Moments::rms() const { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }
core::Vec2 ResidualSums::Moments::mean() const { return n ? core::Vec2(sum / static_cast<double>(n)) : core::Vec2::Zero(); }

void ResidualSums::Pearson::add(double x, double y) {
  n += 1;
  sx += x;
  sy += y;
  sxx += x * x;
  syy += y * y;
  sxy += x * y;
}
void ResidualSums::Pearson::merge(const Pearson& o) {
  n += o.n;
  sx += o.sx;
  sy += o.sy;
  sxx += o.sxx;
  syy += o.syy;
  sxy += o.sxy;
}
double ResidualSums::Pearson::value() const {
  const double vx = n * sxx - sx * sx, vy = n * syy - sy * sy;
  return vx > 0.0 && vy > 0.0 ? (n * sxy - sx * sy) / std::sqrt(vx * vy) : 0.0;
}

ResidualSums::ResidualSums(const LogData& log, const EffectContext& context)
    : log_(&log), base_(core::PerUnitBase::from_rated(context.machine.rated)), regressors_{"|i| [A]",      "i_d [A]",
                                                                                           "i_q [A]",      "speed [pu]",
                                                                                           "|speed| [pu]", "time [s]"} {
  if (log.layout.t_winding) regressors_.emplace_back("T_winding [°C]");
  if (log.layout.t_magnet) regressors_.emplace_back("T_magnet [°C]");
  corr_.resize(regressors_.size());
}

double ResidualSums::regressor(std::size_t j, std::size_t k, const core::Vec2& i, double n_pu) const {
  switch (j) {
    case 0:
      return i.norm();
    case 1:
      return i[0];
    case 2:
      return i[1];
    case 3:
      return n_pu;
    case 4:
      return std::abs(n_pu);
    case 5:
      return log_->t_s(k);
    default:
      break;
  }
  // The temperatures, in the order the constructor lists them: as the models take them (held between a slow
  // sensor's readings); NaN where the row's session has no reading.
  const bool winding = j == 6 && log_->layout.t_winding;
  return (winding ? log_->samples.t_winding_held_C(k) : log_->samples.t_magnet_held_C(k)).value_or(core::kNaN);
}

void ResidualSums::add(std::size_t k, const core::Vec2& nominal_A, const core::Vec2& extended_A) {
  const core::DriveSample s = log_->sample(k);
  const core::Rotation rot = core::Rotation::of(s.theta_el_rad);
  const core::Vec2 i = core::SampleConditioner::logged_current_dq_A(s, rot);
  const double n = s.omega_el_rad_s / base_.omega_el_rad_s;
  all_before_.add(nominal_A);
  all_after_.add(extended_A);
  const bool still = std::abs(n) < kStandstillSpeedPu;
  (still ? still_before_ : moving_before_).add(nominal_A);
  (still ? still_after_ : moving_after_).add(extended_A);
  const int sr = speed_region(n), lr = load_region(i[1], base_.current_A);
  region_before_[sr][lr].add(nominal_A);
  region_after_[sr][lr].add(extended_A);

  if (log_->mode == ModelMode::kTransient) {
    if (!still) {
      ++harmonic_samples_;
      for (int h = 0; h <= kMaxHarmonic; ++h) {
        const std::complex<double> e = std::polar(1.0, -h * s.theta_el_rad);
        harm_before_[h][0] += nominal_A[0] * e;
        harm_before_[h][1] += nominal_A[1] * e;
        harm_after_[h][0] += extended_A[0] * e;
        harm_after_[h][1] += extended_A[1] * e;
      }
    }
    const core::Vec3 i_abc = core::inverse_clarke(core::inverse_park(i, rot));
    const core::Vec3 r_abc_b = core::inverse_clarke(core::inverse_park(nominal_A, rot));
    const core::Vec3 r_abc_a = core::inverse_clarke(core::inverse_park(extended_A, rot));
    for (int x = 0; x < 3; ++x) {
      (i_abc[x] > 0.0 ? pos_before_ : neg_before_)[x].add({r_abc_b[x], 0.0});
      (i_abc[x] > 0.0 ? pos_after_ : neg_after_)[x].add({r_abc_a[x], 0.0});
    }
  }
  for (std::size_t j = 0; j < regressors_.size(); ++j) {
    const double v = regressor(j, k, i, n);
    if (std::isnan(v)) continue;  // a temperature's row without a reading (a slow sensor's, a logger's no-reading)
    corr_[j][0].add(v, nominal_A[0]);
    corr_[j][1].add(v, nominal_A[1]);
    corr_[j][2].add(v, extended_A[0]);
    corr_[j][3].add(v, extended_A[1]);
  }
}

void ResidualSums::merge(const ResidualSums& o) {
  for (int sr = 0; sr < 5; ++sr) {
    for (int lr = 0; lr < 3; ++lr) {
      region_before_[sr][lr].merge(o.region_before_[sr][lr]);
      region_after_[sr][lr].merge(o.region_after_[sr][lr]);
    }
  }
  all_before_.merge(o.all_before_);
  all_after_.merge(o.all_after_);
  still_before_.merge(o.still_before_);
  still_after_.merge(o.still_after_);
  moving_before_.merge(o.moving_before_);
  moving_after_.merge(o.moving_after_);
  for (int h = 0; h <= kMaxHarmonic; ++h) {
    for (int a = 0; a < 2; ++a) {
      harm_before_[h][a] += o.harm_before_[h][a];
      harm_after_[h][a] += o.harm_after_[h][a];
    }
  }
  harmonic_samples_ += o.harmonic_samples_;
  for (int x = 0; x < 3; ++x) {
    pos_before_[x].merge(o.pos_before_[x]);
    pos_after_[x].merge(o.pos_after_[x]);
    neg_before_[x].merge(o.neg_before_[x]);
    neg_after_[x].merge(o.neg_after_[x]);
  }
  for (std::size_t j = 0; j < corr_.size(); ++j) {
    for (int c = 0; c < 4; ++c) corr_[j][c].merge(o.corr_[j][c]);
  }
}

ResidualStatistics ResidualSums::statistics() const {
  ResidualStatistics out;
  out.rms_A = {all_before_.rms(), all_after_.rms()};
  out.standstill_rms_A = {still_before_.rms(), still_after_.rms()};
  out.motion_rms_A = {moving_before_.rms(), moving_after_.rms()};
  out.standstill_samples = still_before_.n;
  out.motion_samples = moving_before_.n;
  for (int sr = 0; sr < 5; ++sr) {
    for (int lr = 0; lr < 3; ++lr) {
      const Moments& b = region_before_[sr][lr];
      // Regions a log only passes through (a few samples in a transient) say little.
      if (static_cast<double>(b.n) < kMinRegionShare * static_cast<double>(all_before_.n) || b.n == 0) continue;
      const Moments& a = region_after_[sr][lr];
      out.regions.push_back({kSpeedRegions[sr],
                             kLoadRegions[lr],
                             b.n,
                             {b.rms(), a.rms()},
                             {b.mean()[0], a.mean()[0]},
                             {b.mean()[1], a.mean()[1]}});
    }
  }
  if (harmonic_samples_ > 0) {
    const double scale = 2.0 / static_cast<double>(harmonic_samples_);
    for (int h = 0; h <= kMaxHarmonic; ++h) {
      // Amplitude of the residual vector's component at h·ϑ (the mean for h = 0).
      const double f = h == 0 ? 0.5 * scale : scale;
      const double before = f * std::hypot(std::abs(harm_before_[h][0]), std::abs(harm_before_[h][1]));
      const double after = f * std::hypot(std::abs(harm_after_[h][0]), std::abs(harm_after_[h][1]));
      out.harmonics.push_back({h, {before, after}});
    }
    for (int x = 0; x < 3; ++x) {
      out.phase_signs.push_back({static_cast<char>('a' + x),
                                 {pos_before_[x].mean()[0], pos_after_[x].mean()[0]},
                                 {neg_before_[x].mean()[0], neg_after_[x].mean()[0]}});
    }
  }
  for (std::size_t j = 0; j < regressors_.size(); ++j) {
    out.correlations.push_back(
        {regressors_[j], {corr_[j][0].value(), corr_[j][2].value()}, {corr_[j][1].value(), corr_[j][3].value()}});
  }
  return out;
}

ResidualStatistics residual_statistics(const LogData& log, const EffectContext& context, const ReplayOutput& nominal,
                                       const ReplayOutput& extended) {
  ResidualSums sums(log, context);
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (nominal.valid[k] && extended.valid[k]) sums.add(k, nominal.residual_A[k], extended.residual_A[k]);
  }
  return sums.statistics();
}

}  // namespace rpem::analysis
