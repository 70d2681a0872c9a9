#pragma once
// The winding sensor's time constant τ_s without the thermal network (docs/derivations.md eq. 14.25): where r̂s
// adapts (standstill with current) it reads the winding through its own law, lagging by the estimator's own
// time constant τ_r; the sensor lags the same winding by τ_s. First-order lags commute, so
//
//   lag_τs(T_rs) = lag_τs(lag_τr(T_w)) = lag_τr(lag_τs(T_w)) = lag_τr(T_sensor)                        (14.25)
//
// whatever the winding did: over runs of steps where both read, τ_s is the least squares of that identity. A copper
// law whose reference is off reads r̂s's winding c kelvin above the sensor's, c one constant for the log, so
//
//   lag_τs(T_rs − c) = lag_τr(T_sensor)                                                                (14.25a)
//
// with c fitted beside τ_s (linear in c: profiled out at each τ_s); unfitted, a few kelvin of c pass for lag. A law
// whose coefficient or reference resistance is off reads the winding through an affine map, not one offset:
//
//   lag_τs(b·T_rs + a) = lag_τr(T_sensor)                                                              (14.25e)
//
// with b and a both fitted (linear: profiled out at each τ_s); with one offset, a 2.4 % coefficient error left the
// independent drive cycle's τ_s 4.2 s [−0.2, 8.5] (not used) against 4.84 s.
// r̂s's own noise, lagged by τ_s, shrinks as τ_s grows and would pull τ_s long: its expected share of the misses is
// taken out (eq. 14.25c), its variance measured from each run's own second differences. A step's r̂s is the mean
// of the samples the step holds, which are an AR(1) from sample to sample: the steps' noise is that AR(1)'s block
// means (eq. 14.25d), more correlated from step to step than the AR(1) over a step's Δt.
// Each run's own least-squares τ_s gives the spread from which the estimate's interval comes.

#include <cstddef>
#include <limits>
#include <vector>

namespace rpem::analysis {

/// One run of consecutive steps where r̂s adapts and the winding sensor reads.
struct SensorLagRun {
  std::vector<double> t_rs_C;    ///< the winding temperature r̂s reads through its law
  std::vector<double> sensor_C;  ///< the sensor's reading
  std::vector<double> tau_r_s;   ///< the estimator's own time constant over each step (the observer's Δt/a)
  std::vector<double> dt_s;      ///< each step's length (from the previous step's end)
  /// The correlation time of r̂s's own noise over each step (the observer's τ_r, eq. 14.25c); empty: none known,
  /// the noise not compensated.
  std::vector<double> rs_noise_tau_s;
  /// How many of r̂s's samples each step's value is the mean of (the step's Δt over the samples' spacing, eq.
  /// 14.25d); empty: one, the step's value a sample of the AR(1) over the step's Δt.
  std::vector<double> rs_samples_per_step;
};

/// r̂s's noise as one step holds it (eq. 14.25d): the mean n_k of m consecutive samples s of an AR(1) of variance
/// v and correlation e^{−x} from sample to sample (x: the samples' spacing over the update's τ_r; ∞: white). Its
/// second moments per unit of v; m = 1 is the AR(1) itself, of correlation e^{−x} from step to step.
struct StepMeanNoise {
  StepMeanNoise(double x, double m);
  double last_to_last = 0.0;  ///< Q = e^{−m·x}: E[s_k·s_{k−1}]/v, s_k the last sample of step k
  double with_last = 1.0;     ///< κ = E[n_k·s_k]/v
  double carry = 0.0;         ///< A = e^{−x}·κ: E[n_k | s_{k−1}] = A·s_{k−1}
  double variance = 1.0;      ///< γ₀ = E[n_k²]/v
  /// E[(n_{k+1} − 2n_k + n_{k−1})²]/v = 6γ₀ − 8γ₁ + 2γ₂, with γ_j = A·Q^{j−1}·κ for j ≥ 1.
  [[nodiscard]] double second_difference() const { return 6.0 * variance - 2.0 * carry * with_last * (4.0 - last_to_last); }
};

/// How the sensor's winding follows r̂s's law reading (eq. 14.25e): T = gain·T_rs + offset_K.
struct SensorLaw {
  double gain = 1.0;
  double offset_K = 0.0;
};

struct SensorLagEstimate {
  double tau_s = std::numeric_limits<double>::quiet_NaN();  ///< pooled least squares over the runs; NaN: none
  /// 95 % interval: the delete-one jackknife over the runs, Student's t (eq. 14.25f; ±∞ with fewer than three runs).
  double lower_s = -std::numeric_limits<double>::infinity(), upper_s = std::numeric_limits<double>::infinity();
  std::size_t runs = 0;
  SensorLaw law;                   ///< (14.25e): the sensor's winding from r̂s's law reading
  double rs_above_sensor_K = 0.0;  ///< how far r̂s's law reads the winding above the sensor, at its mean reading
};

/// r̂s's lag behind the winding it reads (eq. 14.25b), from the observer's τ_r = Δt/a: the update
/// θ⁺ = θ + a·(θ* − θ) on samples Δt apart follows a ramp Δt·(1 − a)/a = τ_r − Δt behind its newest information,
/// which is the sample's own instant, or for a window mean (an averaged log's row) Δt/2 before its end.
[[nodiscard]] double estimator_ramp_lag_s(double tau_r_s, double sample_dt_s, bool window_means);

/// The variance v of the samples of an AR(1) noise, held by a signal as `noise` says (eq. 14.25c, d), from the
/// signal's second differences: E[(Δ²n)²] = `noise.second_difference()`·v ((6 − 8ρ + 2ρ²)·v for the AR(1) itself),
/// the slow signal's own second differences negligible. 0 with fewer than three values.
[[nodiscard]] double correlated_noise_variance(const std::vector<double>& values, const StepMeanNoise& noise);

/// τ_s on [low_s, high_s] from the runs; each run judged after its first `warm` steps (the two
/// lagged signals start from the same reading and need a few time constants to forget it).
[[nodiscard]] SensorLagEstimate sensor_lag_without_network(const std::vector<SensorLagRun>& runs, double low_s,
                                                           double high_s, std::size_t warm);

}  // namespace rpem::analysis
