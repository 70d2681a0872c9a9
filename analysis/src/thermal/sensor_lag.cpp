#include "rpem/analysis/thermal/sensor_lag.hpp"

#include <algorithm>
#include <cmath>

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

/// E[y²] and E[y·n] of y = lag_τs(n) for r̂s's noise n (eq. 14.25c): n an AR(1) of variance v and correlation ρ with
/// the step before, y started at 0 (the run's first reading holds none of it).
struct LaggedNoise {
  double yy = 0.0, yn = 0.0;
  void step(double phi, double rho, double v) {
    const double beta = 0.5 * (1.0 - phi), y_from_n_to = rho * yn;  // E[y_{k−1}·n_k]
    yy = phi * phi * yy + beta * beta * 2.0 * (1.0 + rho) * v + 2.0 * phi * beta * (yn + y_from_n_to);
    yn = phi * y_from_n_to + beta * (1.0 + rho) * v;
  }
};

/// ρ of r̂s's noise between the run's steps: the mean of e^{−Δt/τ_r} over them.
double mean_noise_correlation(const SensorLagRun& x) {
  double sum = 0.0;
  for (std::size_t k = 1; k < x.dt_s.size(); ++k) sum += decay(x.rs_noise_tau_s[k], x.dt_s[k]);
  return x.dt_s.size() > 1 ? sum / static_cast<double>(x.dt_s.size() - 1) : 0.0;
}

/// The sums over the runs (after `warm` steps) that give (14.25a)'s misses at τ_s for any offset c: the residual
/// is e − c·g with e = lag_τs(T_rs) − lag_τr(T_sensor), both started at the run's first reading, and
/// g = lag_τs(1) started at 0 (what lag_τs(T_rs − c) loses to lag_τs(T_rs) per kelvin of c).
struct MissSums {
  double ee = 0.0, eg = 0.0, gg = 0.0;
  double noise = 0.0;  ///< the share of ee that r̂s's noise is expected to make (eq. 14.25c)
  [[nodiscard]] double squared_misses(double c) const { return ee - noise - 2.0 * c * eg + c * c * gg; }
  /// The offset that minimises the misses (0 where no step is judged).
  [[nodiscard]] double best_offset() const { return gg > 0.0 ? eg / gg : 0.0; }
};

/// A run with its noise's ρ and variance (eq. 14.25c), which do not depend on τ_s: found once per run.
struct JudgedRun {
  const SensorLagRun* run = nullptr;
  bool compensated = false;
  double rho = 0.0, v = 0.0;
};

JudgedRun judged(const SensorLagRun& x) {
  JudgedRun j{&x, !x.rs_noise_tau_s.empty(), 0.0, 0.0};
  if (j.compensated) {
    j.rho = mean_noise_correlation(x);
    j.v = correlated_noise_variance(x.t_rs_C, j.rho);
  }
  return j;
}

MissSums miss_sums(const std::vector<JudgedRun>& runs, std::size_t warm, double log_tau) {
  const double tau_s = std::exp(log_tau);
  MissSums m;
  for (const JudgedRun& j : runs) {
    const SensorLagRun* x = j.run;
    double lagged_rs = x->sensor_C.front(), lagged_sensor = x->sensor_C.front(), lagged_one = 0.0;
    LaggedNoise noise;
    for (std::size_t k = 1; k < x->sensor_C.size(); ++k) {
      if (j.compensated) noise.step(decay(tau_s, x->dt_s[k]), j.rho, j.v);
      lagged_rs = lag_step(lagged_rs, x->t_rs_C[k - 1], x->t_rs_C[k], tau_s, x->dt_s[k]);
      lagged_one = lag_step(lagged_one, 1.0, 1.0, tau_s, x->dt_s[k]);
      lagged_sensor = lag_step(lagged_sensor, x->sensor_C[k - 1], x->sensor_C[k], x->tau_r_s[k], x->dt_s[k]);
      if (k < warm) continue;
      const double e = lagged_rs - lagged_sensor;
      m.ee += e * e, m.eg += e * lagged_one, m.gg += lagged_one * lagged_one, m.noise += noise.yy;
    }
  }
  return m;
}

/// τ_s on [lo, hi] (in log τ_s) that minimises (14.25a)'s misses, the offset c profiled out where `offset` is
/// null (c at its least squares for each τ_s), held at `*offset` otherwise.
double best_tau(const std::vector<JudgedRun>& runs, std::size_t warm, double lo, double hi, const double* offset) {
  constexpr double kTolerance = 0.005;  // in log τ_s: 0.5 %
  auto misses = [&](double log_tau) {
    const MissSums m = miss_sums(runs, warm, log_tau);
    return m.squared_misses(offset != nullptr ? *offset : m.best_offset());
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

double correlated_noise_variance(const std::vector<double>& values, double rho) {
  if (values.size() < 3) return 0.0;
  double sum = 0.0;
  for (std::size_t k = 1; k + 1 < values.size(); ++k) {
    const double d = values[k + 1] - 2.0 * values[k] + values[k - 1];
    sum += d * d;
  }
  return sum / static_cast<double>(values.size() - 2) / (6.0 - 8.0 * rho + 2.0 * rho * rho);
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
        r.dt_s.size() == r.sensor_C.size() && (r.rs_noise_tau_s.empty() || r.rs_noise_tau_s.size() == r.sensor_C.size()))
      usable.push_back(judged(r));
  out.runs = usable.size();
  if (usable.empty() || !(low_s > 0.0) || !(high_s > low_s)) return out;
  const double lo = std::log(low_s), hi = std::log(high_s);
  out.tau_s = best_tau(usable, warm, lo, hi, nullptr);
  out.rs_above_sensor_K = miss_sums(usable, warm, std::log(out.tau_s)).best_offset();
  if (usable.size() < 3) return out;
  // Each run's own τ_s at the pooled offset (the law's, one for the log): their spread is the estimate's (runs
  // are independent stretches of the log).
  double sum = 0.0, sum2 = 0.0;
  for (const JudgedRun& r : usable) {
    const double t = best_tau({r}, warm, lo, hi, &out.rs_above_sensor_K);
    sum += t, sum2 += t * t;
  }
  const auto m = static_cast<double>(usable.size());
  const double sd = std::sqrt(std::max(0.0, (sum2 - sum * sum / m) / (m - 1.0)));
  const double half = t975(usable.size() - 1) * sd / std::sqrt(m);
  out.lower_s = out.tau_s - half;
  out.upper_s = out.tau_s + half;
  return out;
}

}  // namespace rpem::analysis
