#include "filter_likelihood.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/normal_quantile.hpp"
#include "rpem/analysis/thermal/golden_section.hpp"
#include "rpem/analysis/thermal/sensor_lag.hpp"
#include "rpem/analysis/thermal/thermal_replay.hpp"
#include "rpem/core/non_finite.hpp"

namespace rpem::analysis {
namespace {

using core::kInf;
/// The range searched for the winding sensor's time constant (eq. 14.22) [s]: from below the filter's step to
/// beyond any end-winding sensor's.
constexpr double kSensorLagLow_s = 0.1, kSensorLagHigh_s = 300.0;

}  // namespace

/// The filter's innovation log-likelihood over the training part.
double training_log_likelihood(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t training) {
  double ll = 0.0;
  for (const FilterStep& s : run_filter(c.fusion, r, training)) ll += s.log_likelihood;
  return ll;
}

/// The value of one of the filter's noise intensities (every node; `field` picks which) that maximises the
/// filter's innovation likelihood over the training part: golden-section search on its log10 in [lo, hi].
double maximum_likelihood(io::ThermalConfig& c, const ThermalRecord& r, std::size_t training,
                          core::ThermalVec core::ThermalFilterConfig::*field, double lo, double hi) {
  auto nll = [&](double log_q) {
    (c.fusion.filter.*field).setZero();
    (c.fusion.filter.*field).head(c.fusion.filter.network.nodes).setConstant(std::pow(10.0, log_q));
    return -training_log_likelihood(c, r, training);
  };
  const double q = std::pow(10.0, golden_section_minimum(nll, lo, hi, 0.02));
  (c.fusion.filter.*field).setZero();
  (c.fusion.filter.*field).head(c.fusion.filter.network.nodes).setConstant(q);
  return q;
}

/// The winding sensor's τ_s without the network (eq. 14.25, rpem/analysis/thermal/sensor_lag.hpp) over the training
/// part's runs of at least kStandstillRun steps in which r̂s adapts and the sensor reads. Used — τ_s set and the
/// winding node taken as the sensor's reading (eq. 14.24) — where at least three runs give a 95 % interval that
/// excludes no lag (its lower end above 0: the rule the likelihood's τ_s follows); otherwise a note, and the
/// likelihood's τ_s after the network.
void sensor_lag_at_standstill(io::ThermalConfig& c, const ThermalRecord& r, std::size_t training, ThermalFitResult& out) {
  constexpr std::size_t kStandstillRun = 60, kWarm = 20;  // steps: a run, and what each lagged side needs to start
  const core::DriftLaw& copper = c.fusion.filter.network.copper;
  const auto rs = static_cast<std::size_t>(core::kRs);
  std::vector<SensorLagRun> runs;
  SensorLagRun run;
  auto close = [&] {
    if (run.sensor_C.size() >= kStandstillRun) runs.push_back(run);
    run = SensorLagRun{};
  };
  for (std::size_t k = 0; k < training && k < r.steps.size(); ++k) {
    if (r.starts_session(k)) close();  // a run does not span two sessions
    const core::ParameterObservation& p = r.steps[k].parameter[rs];
    const double sensor = r.steps[k].winding_sensor_C;
    if (!p.valid || !std::isfinite(sensor) || !(p.time_constant_s >= 0.0)) {
      close();
      continue;
    }
    run.t_rs_C.push_back(copper.temperature_C(p.value));
    run.sensor_C.push_back(sensor);
    run.tau_r_s.push_back(estimator_ramp_lag_s(p.time_constant_s, p.sample_dt_s, r.averaged));
    run.dt_s.push_back(r.steps[k].load.dt_s);
    run.rs_noise_tau_s.push_back(p.time_constant_s);  // r̂s's noise: the update's AR(1) (eq. 14.25c)
    run.rs_samples_per_step.push_back(p.sample_dt_s > 0.0 ? std::max(1.0, r.steps[k].load.dt_s / p.sample_dt_s)
                                                          : 1.0);  // 14.25d
  }
  close();
  const SensorLagEstimate e = sensor_lag_without_network(runs, kSensorLagLow_s, kSensorLagHigh_s, kWarm);
  if (!std::isfinite(e.tau_s)) return;
  const double half = 0.5 * (e.upper_s - e.lower_s) / e.tau_s;
  const bool used = e.runs >= 3 && e.lower_s > 0.0;
  FittedParameter p;
  p.name = "winding sensor time constant (standstill)";
  p.unit = "s";
  p.value = e.tau_s;
  p.half_width_rel = half;  // ∞ with fewer than three runs (the interval's ends are ±∞)
  p.excitation_half_width_rel = p.half_width_rel;
  p.identified = p.half_width_rel <= kIdentifiedHalfWidth;
  out.parameters.push_back(p);
  out.notes.push_back("winding sensor time constant without the network (eq. 14.25, " + std::to_string(e.runs) +
                      " standstill runs of r̂s beside the sensor): " + std::to_string(e.tau_s) + " s, 95 % interval [" +
                      std::to_string(e.lower_s) + ", " + std::to_string(e.upper_s) + "] s, fitted beside r̂s's law reading " +
                      std::to_string(e.rs_above_sensor_K) + " K above the sensor at its runs' mean, " +
                      std::to_string(1.0 / e.law.gain) + " K per kelvin of the sensor's (eq. 14.25e); " +
                      (used         ? "used, the winding node standing for the sensor's reading (eq. 14.24)"
                       : e.runs < 3 ? "not used (fewer than three runs)"
                                    : "not used (its interval reaches down to no lag at all)"));
  if (!used) return;
  c.fusion.winding_sensor_time_constant_s = e.tau_s;
  c.fusion.winding_node_is_reading = true;
}

/// The winding sensor's time constant τ_s (eq. 14.22) that maximises the filter's innovation likelihood over the
/// training part, on the fitted network: golden-section search on log τ_s in [kSensorLagLow_s, kSensorLagHigh_s],
/// its 95 % interval where the −log-likelihood has risen by χ²₁(0.95)/2 (a profile-likelihood interval; ∞ where
/// it does not rise so far within the range). Used (written to the configuration) only where the no-lag model
/// (τ_s = 0) lies outside that interval; otherwise 0 and a note. A network fit with τ_s among its parameters
/// compares the open-loop network with the sensor, whose misses there are the network's own (2026-11-27,
/// docs/thermal.md): the filter's innovations see the lag where the model does not hide it.
void fit_sensor_lag(io::ThermalConfig& c, const ThermalRecord& r, std::size_t training, ThermalFitResult& out) {
  auto nll = [&](double log_tau) {
    c.fusion.winding_sensor_time_constant_s = log_tau == -kInf ? 0.0 : std::exp(log_tau);
    return -training_log_likelihood(c, r, training);
  };
  // χ²₁(0.95)/2: the rise of the −log-likelihood that bounds a 95 % profile-likelihood interval (Wilks).
  const double half_chi2_95 = likelihood_ratio_threshold(1);
  const double lo = std::log(kSensorLagLow_s), hi = std::log(kSensorLagHigh_s);
  const double best = golden_section_minimum(nll, lo, hi, 0.01), f_best = nll(best), f_none = nll(-kInf);
  // The interval's ends: bisection on log τ_s between the optimum and the range's end.
  auto end = [&](double edge) {
    if (nll(edge) - f_best < half_chi2_95) return edge == lo ? -kInf : kInf;
    double in = best, outside = edge;
    while (std::abs(outside - in) > 0.01) {
      const double mid = 0.5 * (in + outside);
      (nll(mid) - f_best < half_chi2_95 ? in : outside) = mid;
    }
    return 0.5 * (in + outside);
  };
  const double lower = end(lo), upper = end(hi);
  FittedParameter p;
  p.name = "winding sensor time constant";
  p.unit = "s";
  p.value = std::exp(best);
  p.half_width_rel = std::isfinite(lower) && std::isfinite(upper) ? std::expm1(0.5 * (upper - lower)) : kInf;
  p.excitation_half_width_rel = p.half_width_rel;
  p.identified = p.half_width_rel <= kIdentifiedHalfWidth;
  out.parameters.push_back(p);
  const bool lag_shown = f_none - f_best >= half_chi2_95;
  out.notes.push_back("winding sensor time constant: " + std::to_string(p.value) + " s, 95 % interval [" +
                      std::to_string(std::exp(lower)) + ", " + std::to_string(std::exp(upper)) +
                      "] s (profile likelihood of the filter's innovations); " +
                      (lag_shown ? "used" : "no lag (0) is within it: not used, the sensor is taken as the node"));
  c.fusion.winding_sensor_time_constant_s = lag_shown ? p.value : 0.0;
}

/// What a chosen τ_d must gain over the walk. The walk is the nested model (τ_d → ∞), so a finite τ_d is one more
/// parameter: 2·ΔlnL > χ²₁(1 − 0.05/m) = z², z the normal quantile at 1 − 0.05/(2m) (eq. 14.21a).
double likelihood_ratio_threshold(std::size_t trials) {
  constexpr double kAlpha = 0.05;  // the fit's 95 % intervals' level
  const double z = upper_normal_quantile(0.5 * kAlpha / static_cast<double>(std::max<std::size_t>(trials, 1)));
  return 0.5 * z * z;
}

/// The disturbances' correlation times τ_d (eq. 14.19) jointly with q_d, by the training part's innovation
/// likelihood. On a log-spaced grid (half decades from 300 s to 10⁵ s, beside the walk) q_d is refitted at each
/// τ_d and the pair of the highest likelihood kept. A grid, not a search: the likelihood in τ_d is flat towards
/// the walk and need not be unimodal, and six points bracket the network's time constants (minutes) to a log's
/// length (hours). Per node, each in turn (winding first, the others held at their choice so far): the nodes'
/// disturbances have different causes (docs/thermal.md, "A Gauss–Markov disturbance": one τ_d for the network
/// let the magnet's choice decide the winding's). A given τ_d is every node's.
void choose_disturbance_time_constants(ThermalFitResult& out, const ThermalRecord& record, std::size_t training,
                                       const ThermalFitOptions& options) {
  core::ThermalFilterConfig& f = out.config.fusion.filter;
  const int nodes = f.network.nodes;
  f.disturbance_time_constant_s.setConstant(kInf);
  std::vector<double> grid;
  if (std::isnan(options.disturbance_time_constant_s)) {
    for (double log_tau = 2.5; log_tau <= 5.0 + 1e-9; log_tau += 0.5) grid.push_back(std::pow(10.0, log_tau));
  } else if (options.disturbance_time_constant_s < 1e9) {
    grid.push_back(options.disturbance_time_constant_s);
  }
  const auto fit_q = [&] {
    return maximum_likelihood(out.config, record, training, &core::ThermalFilterConfig::disturbance_W2_per_s, -6.0, 4.0);
  };
  double best_ll = training_log_likelihood(out.config, record, training);
  out.disturbance_time_constant_log_likelihood.push_back({-1, kInf, best_ll});
  const bool given = !std::isnan(options.disturbance_time_constant_s);
  if (given) best_ll = -kInf;  // a given τ_d is kept whatever the walk's likelihood
  std::vector<int> order;      // the network at once (−1), or each node in turn
  if (!given) {
    order.push_back(f.network.winding);
    for (int i = 0; i < nodes; ++i)
      if (i != f.network.winding) order.push_back(i);
  } else {
    order.push_back(-1);
  }
  core::ThermalVec best_tau = f.disturbance_time_constant_s;
  core::ThermalVec best_q = f.disturbance_W2_per_s;
  double best_q_scalar = out.disturbance_W2_per_s;
  // A given τ_d is taken whatever the likelihood; a chosen one must pass the test (eq. 14.21a).
  const double threshold = given ? 0.0 : likelihood_ratio_threshold(grid.size());
  out.disturbance_time_constant_threshold = threshold;
  for (int node : order) {
    // The grid's best for this node (the grid's points have the same number of parameters: plain comparison),
    // then against the choice so far (the walk, or what the nodes before chose) by the test.
    double node_ll = -kInf, node_q_scalar = best_q_scalar;
    core::ThermalVec node_tau = best_tau, node_q = best_q;
    for (double tau_s : grid) {
      f.disturbance_time_constant_s = best_tau;
      if (node < 0) {
        f.disturbance_time_constant_s.head(nodes).setConstant(tau_s);
      } else {
        f.disturbance_time_constant_s[node] = tau_s;
      }
      const double q = fit_q();
      const double ll = training_log_likelihood(out.config, record, training);
      out.disturbance_time_constant_log_likelihood.push_back({node, tau_s, ll});
      if (ll > node_ll) {
        node_ll = ll;
        node_q_scalar = q;
        node_q = f.disturbance_W2_per_s;
        node_tau = f.disturbance_time_constant_s;
      }
    }
    if (node_ll > best_ll + threshold) {
      best_ll = node_ll;
      best_q_scalar = node_q_scalar;
      best_q = node_q;
      best_tau = node_tau;
    }
  }
  f.disturbance_time_constant_s = best_tau;
  f.disturbance_W2_per_s = best_q;
  out.disturbance_W2_per_s = best_q_scalar;
  out.disturbance_time_constant_s = best_tau;
}

}  // namespace rpem::analysis
