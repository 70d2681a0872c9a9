#include "rpem/analysis/thermal/sensor_lag.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "rpem/analysis/thermal/golden_section.hpp"

namespace rpem::analysis {
namespace {

/// e^{−Δt/τ}; 0 for τ = 0 (no lag, no correlation).
double decay(double tau_s, double dt_s) { return tau_s > 0.0 ? std::exp(-dt_s / tau_s) : 0.0; }

/// One step of a first-order lag of time constant τ under an input moving linearly over the step (exact for
/// τ ≫ Δt, the trapezoid's mean otherwise); τ = 0 passes the input through.
double lag_step(double y, double u_from, double u_to, double tau_s, double dt_s) {
  const double phi = decay(tau_s, dt_s);
  return phi * y + (1.0 - phi) * 0.5 * (u_from + u_to);
}

/// E[y²] of y = lag_τs(n) for r̂s's noise n (eq. 14.25c, d): n_k the mean of step k's samples s, an AR(1) of
/// variance v; y started at 0 (the run's first reading holds none of it). The moments carried: E[y²], E[y·n] and
/// E[y·s] with n and s of the step last lagged; the new step's n_k = A·s_{k−1} + w_k, w_k independent of the past.
struct LaggedNoise {
  double yy = 0.0, yn = 0.0, ys = 0.0;
  void step(double phi, const StepMeanNoise& n, double v) {
    const double beta = 0.5 * (1.0 - phi), a = n.carry, q = n.last_to_last;
    const double ny = ys * a;  // E[y_{k−1}·n_k]
    yy = phi * phi * yy + 2.0 * beta * beta * (n.variance + a * n.with_last) * v + 2.0 * phi * beta * (yn + ny);
    yn = phi * ny + beta * (n.variance + a * n.with_last) * v;
    ys = phi * q * ys + beta * (1.0 + q) * n.with_last * v;
  }
};

/// r̂s's noise over the run (eq. 14.25d): x from the mean over its steps of the sample-to-sample correlation
/// e^{−Δt/(m·τ_r)}, m the mean of the samples per step (one where not given).
StepMeanNoise run_noise(const SensorLagRun& x) {
  double q = 0.0, m = 0.0;
  for (std::size_t k = 1; k < x.dt_s.size(); ++k) {
    const double samples = x.rs_samples_per_step.empty() ? 1.0 : x.rs_samples_per_step[k];
    q += decay(x.rs_noise_tau_s[k], x.dt_s[k] / samples);
    m += samples;
  }
  const double steps = static_cast<double>(std::max<std::size_t>(1, x.dt_s.size() - 1));
  constexpr double kMinX = 1e-6;  // a step of no length: correlation 1, which the block's sums cannot divide by
  return {std::max(kMinX, -std::log(q / steps)), std::max(1.0, m / steps)};
}

/// The sums over the runs (after `warm` steps) that give (14.25e)'s misses at τ_s for any law (b, a): the residual
/// is e + d·z + a·g with d = b − 1, e = lag_τs(T_rs) − lag_τr(T_sensor), both started at the run's first reading,
/// z = lag_τs(T_rs) and g = lag_τs(1), both started at 0 (what b and a add per unit). r̂s's noise enters through
/// b·z: its expected share (1 + d)²·N is taken out (eq. 14.25c), which makes the law's least squares a corrected one
/// (z's noise would otherwise pull d down).
struct MissSums {
  double ee = 0.0, ez = 0.0, eg = 0.0, zz = 0.0, zg = 0.0, gg = 0.0;
  double noise = 0.0;     ///< N: the share of ee that r̂s's noise is expected to make (eq. 14.25c)
  double t_rs_sum = 0.0;  ///< Σ T_rs over the judged steps (their mean: where the law's offset is said)
  double judged = 0.0;    ///< judged steps
  [[nodiscard]] double squared_misses(const SensorLaw& law) const {
    const double d = law.gain - 1.0, a = law.offset_K;
    return ee + 2.0 * d * ez + 2.0 * a * eg + d * d * zz + 2.0 * d * a * zg + a * a * gg - law.gain * law.gain * noise;
  }
  /// The law that minimises the misses: the 2×2 normal equations in (d, a); where the runs' temperatures do not
  /// tell a gain from an offset (z a multiple of g: the determinant below a millionth of its terms), the gain is 1.
  [[nodiscard]] SensorLaw best_law() const {
    if (!(gg > 0.0)) return {};
    const double zz_c = zz - noise;  // (z's noise taken out)
    const double det = zz_c * gg - zg * zg;
    if (det > 1e-6 * std::abs(zz_c * gg)) {
      const double rhs_d = noise - ez, rhs_a = -eg;
      const double d = (rhs_d * gg - zg * rhs_a) / det, a = (zz_c * rhs_a - zg * rhs_d) / det;
      return {1.0 + d, a};
    }
    return {1.0, -eg / gg};
  }
};

/// A run with its noise's correlation and variance (eq. 14.25c, d), which do not depend on τ_s: found once per run.
struct JudgedRun {
  const SensorLagRun* run = nullptr;
  bool compensated = false;
  StepMeanNoise noise{std::numeric_limits<double>::infinity(), 1.0};
  double v = 0.0;
};

JudgedRun judged(const SensorLagRun& x) {
  JudgedRun j;
  j.run = &x;
  j.compensated = !x.rs_noise_tau_s.empty();
  if (j.compensated) {
    j.noise = run_noise(x);
    j.v = correlated_noise_variance(x.t_rs_C, j.noise);
  }
  return j;
}

MissSums miss_sums(const std::vector<JudgedRun>& runs, std::size_t warm, double log_tau) {
  const double tau_s = std::exp(log_tau);
  MissSums m;
  for (const JudgedRun& j : runs) {
    const SensorLagRun* x = j.run;
    double lagged_rs = x->sensor_C.front(), lagged_sensor = x->sensor_C.front(), lagged_one = 0.0, lagged_law = 0.0;
    LaggedNoise noise;
    for (std::size_t k = 1; k < x->sensor_C.size(); ++k) {
      if (j.compensated) noise.step(decay(tau_s, x->dt_s[k]), j.noise, j.v);
      lagged_rs = lag_step(lagged_rs, x->t_rs_C[k - 1], x->t_rs_C[k], tau_s, x->dt_s[k]);
      lagged_one = lag_step(lagged_one, 1.0, 1.0, tau_s, x->dt_s[k]);
      lagged_law = lag_step(lagged_law, x->t_rs_C[k - 1], x->t_rs_C[k], tau_s, x->dt_s[k]);
      lagged_sensor = lag_step(lagged_sensor, x->sensor_C[k - 1], x->sensor_C[k], x->tau_r_s[k], x->dt_s[k]);
      if (k < warm) continue;
      const double e = lagged_rs - lagged_sensor;
      m.ee += e * e, m.ez += e * lagged_law, m.eg += e * lagged_one;
      m.zz += lagged_law * lagged_law, m.zg += lagged_law * lagged_one, m.gg += lagged_one * lagged_one;
      m.noise += noise.yy, m.t_rs_sum += x->t_rs_C[k], m.judged += 1.0;
    }
  }
  return m;
}

/// τ_s on [lo, hi] (in log τ_s) that minimises (14.25e)'s misses, the law profiled out (at its least squares for each
/// τ_s).
double best_tau(const std::vector<JudgedRun>& runs, std::size_t warm, double lo, double hi) {
  // In log τ_s: 0.05 %, well below the differences between the jackknife's fits (eq. 14.25f).
  constexpr double kTolerance = 0.0005;
  auto misses = [&](double log_tau) {
    const MissSums m = miss_sums(runs, warm, log_tau);
    return m.squared_misses(m.best_law());
  };
  return std::exp(golden_section_minimum(misses, lo, hi, kTolerance));
}

/// Student's t quantile at 0.975 for ν degrees of freedom (table for ν ≤ 10, the normal's beyond 30).
double t975(std::size_t nu) {
  constexpr double kTable[] = {0.0, 12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228};
  if (nu <= 10) return kTable[nu];
  return nu <= 30 ? 2.228 - (2.228 - 2.042) * static_cast<double>(nu - 10) / 20.0 : 1.960;
}

}  // namespace

namespace {

/// (1/m)·Σ_{t<m} e^{−t·x}: the block mean's weight on its last sample's past (eq. 14.25d).
double block_weight(double x, double m) { return std::expm1(-m * x) / (m * std::expm1(-x)); }

/// γ₀/v: the variance of the mean of m consecutive samples of an AR(1) of correlation q = e^{−x}, per unit of its own.
double block_variance(double x, double m) {
  const double q = std::exp(-x), one_q = -std::expm1(-x), one_Q = -std::expm1(-m * x);
  return (m * (1.0 + q) / one_q - 2.0 * q * one_Q / (one_q * one_q)) / (m * m);
}

}  // namespace

StepMeanNoise::StepMeanNoise(double x, double m)
    : last_to_last(std::exp(-m * x)),
      with_last(block_weight(x, m)),
      carry(std::exp(-x) * with_last),
      variance(block_variance(x, m)) {
  assert(x > 0.0 && m >= 1.0);  // x = ∞: white samples (e^{−x} = 0)
}

double correlated_noise_variance(const std::vector<double>& values, const StepMeanNoise& noise) {
  if (values.size() < 3) return 0.0;
  double sum = 0.0;
  for (std::size_t k = 1; k + 1 < values.size(); ++k) {
    const double d = values[k + 1] - 2.0 * values[k] + values[k - 1];
    sum += d * d;
  }
  return sum / static_cast<double>(values.size() - 2) / noise.second_difference();
}

double estimator_ramp_lag_s(double tau_r_s, double sample_dt_s, bool window_means) {
  return std::max(0.0, tau_r_s - (window_means ? 0.5 : 1.0) * sample_dt_s);
}

SensorLagEstimate sensor_lag_without_network(const std::vector<SensorLagRun>& runs, double low_s, double high_s,
                                             std::size_t warm) {
  SensorLagEstimate out;
  std::vector<JudgedRun> usable;
  for (const SensorLagRun& r : runs)
    if (r.sensor_C.size() > warm && r.t_rs_C.size() == r.sensor_C.size() && r.tau_r_s.size() == r.sensor_C.size() &&
        r.dt_s.size() == r.sensor_C.size() && (r.rs_noise_tau_s.empty() || r.rs_noise_tau_s.size() == r.sensor_C.size()) &&
        (r.rs_samples_per_step.empty() || r.rs_samples_per_step.size() == r.sensor_C.size()))
      usable.push_back(judged(r));
  out.runs = usable.size();
  if (usable.empty() || !(low_s > 0.0) || !(high_s > low_s)) return out;
  const double lo = std::log(low_s), hi = std::log(high_s);
  out.tau_s = best_tau(usable, warm, lo, hi);
  const MissSums at_best = miss_sums(usable, warm, std::log(out.tau_s));
  out.law = at_best.best_law();
  // Where r̂s's law reads the winding above the sensor, at the mean of its judged readings: T̄ − (b·T̄ + a).
  const double mean_rs_C = at_best.judged > 0.0 ? at_best.t_rs_sum / at_best.judged : 0.0;
  out.rs_above_sensor_K = mean_rs_C - (out.law.gain * mean_rs_C + out.law.offset_K);
  if (usable.size() < 3) return out;
  // The delete-one jackknife over the runs (eq. 14.25f): the pooled fit, law and all, with each run left out in turn.
  // The runs are independent stretches of the log; refitting the law each time carries its error into τ_s.
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t left_out = 0; left_out < usable.size(); ++left_out) {
    std::vector<JudgedRun> rest;
    rest.reserve(usable.size() - 1);
    for (std::size_t k = 0; k < usable.size(); ++k)
      if (k != left_out) rest.push_back(usable[k]);
    const double t = best_tau(rest, warm, lo, hi);
    sum += t, sum2 += t * t;
  }
  const auto m = static_cast<double>(usable.size());
  const double se = std::sqrt(std::max(0.0, (m - 1.0) / m * (sum2 - sum * sum / m)));
  const double half = t975(usable.size() - 1) * se;
  out.lower_s = out.tau_s - half;
  out.upper_s = out.tau_s + half;
  return out;
}

}  // namespace rpem::analysis
