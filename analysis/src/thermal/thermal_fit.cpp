#include "rpem/analysis/thermal/thermal_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "../median.hpp"
#include "filter_likelihood.hpp"
#include "network_layout.hpp"
#include "rpem/analysis/cluster_robust.hpp"
#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/thermal/thermal_replay.hpp"
#include "rpem/analysis/thermal/thermal_report.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/io/errors.hpp"

namespace rpem::analysis {
namespace {

using core::kInf;
using network::Layout;
using network::LossTie;
using network::Slot;
using network::SlotKind;
/// The floor of an observation's σ in the fit's weights: temperatures are not resolved finer [K].
constexpr double kSigmaFloor_K = 0.5;
/// Each log parameter stays within e^±this of its start (a factor of 3·10⁴): finite simulations only.
constexpr double kLogRange = 10.3;
/// The prior of each logarithmic parameter: normal about the start with a standard deviation of one decade
/// (docs/thermal.md, "The fit"): it decides only where the log leaves a direction undetermined. The copper
/// loss's scale is known better: (3/2)·R_s·|i|² within a factor of 2 (AC resistance, stray load losses).
constexpr double kPriorSigmaLog = 2.302585092994046;
constexpr double kPriorSigmaLogCopper = 0.6931471805599453;

/// One observation the fit compares the network with: step, kind (0 ψ̂m, 1 r̂s, 2 winding sensor), weight.
struct Point {
  std::size_t step;
  int kind;
  double sigma_K;
};

/// The winding sensor's lag over step `s` of the open-loop network, at its temperatures `t` at the step's end
/// (eq. 14.22, as the filter does it: core/thermal_sensor.hpp; the network's rate is exact here, variance 0);
/// `rates`: the network's at s.load.
void advance_sensor_lag(const core::ThermalFusionConfig& f, const core::ThermalStepData& s, const core::ThermalRates& rates,
                        const core::ThermalVec& t, core::SensorLag& lag) {
  if (!(f.winding_sensor_time_constant_s > 0.0) || f.winding_node_is_reading) return;
  const core::WindingRate g = core::winding_rate(f.filter.network, rates);
  lag.advance(core::sensor_lag_step(f.winding_sensor_time_constant_s, s.load.dt_s, s.winding_sensor_age),
              g.row.head<core::kMaxThermalNodes>().dot(t) + g.constant_K_per_s, 0.0);
}

/// The observation's miss in kelvin: (y − h·T − c)/(∂y/∂T of its own node).
double miss_K(const core::StepObservations& o, int kind, const core::ThermalVec& t, int own_node) {
  const core::ThermalObservation& x = o.item[static_cast<std::size_t>(kind)];
  // A sensor reads kelvin: its miss is not scaled by its h on the node (1 − κ·A_ww with a lag, eq. 14.22).
  return (x.value - x.h.dot(t) - x.offset) / (kind == 2 ? 1.0 : x.h[own_node]);
}

int own_node(const core::ThermalNetwork& n, int kind) { return kind == 0 ? n.magnet : n.winding; }

/// Residuals of a configuration at the given points: the open-loop network against each observation, weighted.
/// A network whose temperatures leave this band has run away (a copper loss growing faster with the
/// winding's temperature than its conductances carry it off): its remaining residuals are kRunaway.
constexpr double kRunawayBand_K = 2000.0;
constexpr double kRunaway = 1e6;

void residuals(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t steps, const std::vector<Point>& points,
               double* out) {
  const core::ThermalFusionConfig& f = c.fusion;
  core::ThermalVec t;
  core::SensorLag lag;
  std::size_t p = 0;
  for (std::size_t k = 0; k < steps && p < points.size(); ++k) {
    const core::ThermalStepData& s = r.steps[k];
    if (r.starts_session(k)) {  // each session from its own start (as simulate_open_loop)
      t = core::start_temperatures_C(f, s);
      lag = core::SensorLag{};
    }
    const core::ThermalRates rates = core::thermal_rates(f.filter.network, s.load);  // once: three uses
    const core::ThermalTransition tr = core::thermal_transition(f.filter.network, rates, s.load.dt_s);
    t = tr.phi * t + tr.gamma;
    if (!(t.cwiseAbs().maxCoeff() < kRunawayBand_K)) break;
    if (points[p].step == k) {
      const core::StepObservations o = core::step_observations(f, s, rates, t, core::ThermalVec::Zero(), lag);
      for (; p < points.size() && points[p].step == k; ++p) {
        const double m = miss_K(o, points[p].kind, t, own_node(f.filter.network, points[p].kind));
        out[p] = std::isfinite(m) ? std::clamp(m / points[p].sigma_K, -kRunaway, kRunaway) : kRunaway;
      }
    }
    advance_sensor_lag(f, s, rates, t, lag);
  }
  for (; p < points.size(); ++p) out[p] = kRunaway;
}

/// The weighted residuals and, after them, the prior's: (x − x_prior)/σ_prior per logarithmic parameter.
class Cost {
 public:
  Cost(const Layout& layout, const ThermalRecord& r, std::size_t steps, const std::vector<Point>& points,
       const std::vector<double>& prior)
      : layout_(layout), record_(r), steps_(steps), points_(points), prior_(prior) {}
  bool operator()(double const* const* x, double* out) const {
    residuals(layout_.apply(x[0]), record_, steps_, points_, out);
    for (std::size_t k = 0; k < prior_.size(); ++k) {
      const double sigma = layout_.slots()[k].kind == SlotKind::kCopperScale ? kPriorSigmaLogCopper : kPriorSigmaLog;
      out[points_.size() + k] = (x[0][k] - prior_[k]) / sigma;
    }
    return true;
  }

 private:
  const Layout& layout_;
  const ThermalRecord& record_;
  std::size_t steps_;
  const std::vector<Point>& points_;
  std::vector<double> prior_;
};

/// The observations of the training part and their weights (fixed: the estimator's σ at the observed
/// temperature, floored; the winding sensor's configured σ).
std::vector<Point> training_points(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t steps) {
  std::vector<Point> points;
  const core::ThermalFusionConfig& f = c.fusion;
  for (std::size_t k = 0; k < steps; ++k) {
    const core::StepObservations o =
        core::step_observations(f, r.steps[k], core::ThermalVec::Zero(), core::ThermalVec::Zero());
    for (int kind = 0; kind < 3; ++kind) {
      if (!o.present[static_cast<std::size_t>(kind)]) continue;
      double sigma = 0.0;
      if (kind == 2) {
        sigma = f.winding_sensor_sigma_K;
      } else {
        const core::ParameterObservation& p = r.steps[k].parameter[static_cast<std::size_t>(kind)];
        const double slope = o.item[static_cast<std::size_t>(kind)].h[own_node(f.filter.network, kind)];
        sigma = std::sqrt(p.variance) / std::abs(slope);
      }
      points.push_back({k, kind, std::hypot(sigma, kSigmaFloor_K)});
    }
  }
  return points;
}

struct Solved {
  std::vector<double> x;
  double cost = kInf;
};

Solved solve(const Layout& layout, const ThermalRecord& r, std::size_t steps, const std::vector<Point>& points,
             const std::vector<double>& prior, std::vector<double> x, int max_iterations) {
  ceres::NumericDiffOptions diff;
  diff.relative_step_size = 1e-6;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<Cost, ceres::CENTRAL>(new Cost(layout, r, steps, points, prior),
                                                                               ceres::TAKE_OWNERSHIP, diff);
  cost->AddParameterBlock(static_cast<int>(x.size()));
  cost->SetNumResiduals(static_cast<int>(points.size() + prior.size()));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data());
  const std::vector<double> x0 = x;
  for (std::size_t k = 0; k < x.size(); ++k) {
    problem.SetParameterLowerBound(x.data(), static_cast<int>(k), x0[k] - kLogRange);
    problem.SetParameterUpperBound(x.data(), static_cast<int>(k), x0[k] + kLogRange);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-10;
  options.parameter_tolerance = 1e-10;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return {x, 2.0 * summary.final_cost};
}

/// Forward-difference Jacobian of the weighted residuals at x (columns per parameter).
Eigen::MatrixXd jacobian(const Layout& layout, const ThermalRecord& r, std::size_t steps, const std::vector<Point>& points,
                         const std::vector<double>& x, std::vector<double>& r0) {
  r0.assign(points.size(), 0.0);
  residuals(layout.apply(x.data()), r, steps, points, r0.data());
  Eigen::MatrixXd j(static_cast<Eigen::Index>(points.size()), static_cast<Eigen::Index>(x.size()));
  std::vector<double> moved(points.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    std::vector<double> xk = x;
    const double h = 1e-5;
    xk[k] += h;
    residuals(layout.apply(xk.data()), r, steps, points, moved.data());
    for (std::size_t p = 0; p < points.size(); ++p)
      j(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(k)) = (moved[p] - r0[p]) / h;
  }
  return j;
}

/// Intervals and the weak directions (cluster-robust sandwich over equal-time blocks of the training part,
/// as EffectFitter::intervals does for `rpem diagnose`).
void intervals(const Layout& layout, const ThermalRecord& r, std::size_t steps, const std::vector<Point>& points,
               const std::vector<double>& x, int blocks, ThermalFitResult& out) {
  std::vector<double> r0;
  const Eigen::MatrixXd j = jacobian(layout, r, steps, points, x, r0);
  const Eigen::Index n = j.cols();
  const double t0 = r.t_s.front(), t1 = r.t_s[steps - 1];
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, blocks);
  for (std::size_t p = 0; p < points.size(); ++p) {
    const double frac = (r.t_s[points[p].step] - t0) / std::max(t1 - t0, 1e-9);
    const auto b = static_cast<Eigen::Index>(std::min(blocks - 1, static_cast<int>(frac * blocks)));
    g.col(b) += j.row(static_cast<Eigen::Index>(p)).transpose() * r0[p];
  }
  const Eigen::MatrixXd h = j.transpose() * j;
  const ClusterRobustCovariance cov = cluster_robust_covariance(h, g);
  const Eigen::MatrixXd& h_inv = cov.excitation;
  const Eigen::MatrixXd& robust = cov.robust;
  const io::ThermalConfig fitted = layout.apply(x.data());
  for (std::size_t k = 0; k < layout.size(); ++k) {
    const Slot& s = layout.slots()[k];
    const auto kk = static_cast<Eigen::Index>(k);
    FittedParameter p;
    p.name = s.name;
    p.unit = s.unit;
    p.value = Layout::quantity(fitted, s);
    const bool excited = cov.excited(kk);
    auto rel = [&](double variance) {
      if (!excited) return kInf;
      const double half = kZ95 * std::sqrt(std::max(variance, 0.0));
      return std::expm1(half);
    };
    p.half_width_rel = rel(robust(kk, kk));
    p.excitation_half_width_rel = rel(h_inv(kk, kk));
    p.identified = p.half_width_rel <= kIdentifiedHalfWidth;
    out.parameters.push_back(p);
    // A loss term's relative uncertainty for the filter's disturbance (thermal_filter.hpp): its robust
    // standard deviation, at most 1 (a term the log cannot pin is uncertain by its own size).
    const double sigma = excited ? std::min(1.0, std::expm1(std::sqrt(std::max(robust(kk, kk), 0.0)))) : 1.0;
    if (s.kind == SlotKind::kLoss) {
      for (int f = 0; f < core::kLossForms; ++f) {
        if (s.share[static_cast<std::size_t>(f)] > 0.0) out.config.fusion.filter.loss_rel_sigma(f, s.i) = sigma;
      }
    }
    // The copper loss's: its scale's, at least the winding law's coefficient spread (R_s at a temperature).
    if (s.kind == SlotKind::kCopperScale) {
      const double law = out.config.fusion.filter.calibration_sigma[static_cast<int>(core::Calibration::kCopperCoefficient)];
      out.config.fusion.filter.copper_rel_sigma = std::max(sigma, law);
    }
  }
  // Weak directions: eigenvectors of the correlation form of JᵀJ with eigenvalues below 10⁻⁴ of the largest.
  Eigen::VectorXd d = h.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd corr = d.asDiagonal() * h * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ce(corr);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (ce.eigenvalues()[k] > 1e-4 * ce.eigenvalues().maxCoeff()) continue;
    std::string text;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (std::abs(ce.eigenvectors()(i, k)) < 0.3) continue;
      text += (text.empty() ? "" : ", ") + layout.slots()[static_cast<std::size_t>(i)].name;
    }
    if (!text.empty()) out.not_identifiable.push_back(text);
  }
}

/// A winding sensor's σ where the configuration fuses none: the sensor is still read (judged, the soak test).
constexpr double kUnfusedWindingSensorSigma_K = 1.0;

/// RMS of the network's misses on each observed signal, training and held out; what the training part observes of
/// each (the temperatures its `points` read, their σ).
void judge(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t training, const std::vector<Point>& points,
           ThermalFitResult& out) {
  const core::ThermalFusionConfig& f = c.fusion;
  out.open_loop_C = simulate_open_loop(f, r);
  const char* names[3] = {"magnet (from psi_m)", "winding (from r_s)", "winding sensor"};
  // The sensor is judged on every step that has one, whether or not the configuration fuses it.
  core::ThermalFusionConfig judged = f;
  if (judged.winding_sensor_sigma_K <= 0.0) judged.winding_sensor_sigma_K = kUnfusedWindingSensorSigma_K;
  std::vector<core::SensorLag> lag(r.steps.size());  // at each step's start
  for (std::size_t k = 0; k + 1 < r.steps.size(); ++k) {
    if (r.starts_session(k + 1)) continue;  // a session's first step starts without a lag
    lag[k + 1] = lag[k];
    advance_sensor_lag(judged, r.steps[k], core::thermal_rates(f.filter.network, r.steps[k].load), out.open_loop_C[k],
                       lag[k + 1]);
  }
  for (int kind = 0; kind < 3; ++kind) {
    SignalFit s;
    s.name = names[kind];
    double fit2 = 0.0, held2 = 0.0;
    std::vector<double> observed_C;
    const int own = own_node(f.filter.network, kind);
    for (std::size_t k = 0; k < r.steps.size(); ++k) {
      const core::StepObservations o =
          core::step_observations(judged, r.steps[k], out.open_loop_C[k], core::ThermalVec::Zero(), lag[k]);
      if (!o.present[static_cast<std::size_t>(kind)]) continue;
      const double m = miss_K(o, kind, out.open_loop_C[k], own);
      if (k < training) {
        fit2 += m * m;
        ++s.fit_points;
        // The temperature observed: the sensor's reading; a parameter's, its node's at the network's other nodes
        // (the observation is linear in T: y − c − h·T = h_own·m).
        observed_C.push_back(kind == 2 ? r.steps[k].winding_sensor_C : out.open_loop_C[k][own] + m);
      } else {
        held2 += m * m;
        ++s.heldout_points;
        s.heldout_worst_K = std::max(s.heldout_worst_K, std::abs(m));
      }
    }
    if (s.fit_points + s.heldout_points == 0) continue;
    s.training_low_C = observed_C.empty() ? core::kNaN : quantile(observed_C, 0.05);
    s.training_high_C = observed_C.empty() ? core::kNaN : quantile(observed_C, 0.95);
    std::vector<double> sigma_K;
    for (const Point& p : points) {
      if (p.kind == kind) sigma_K.push_back(p.sigma_K);
    }
    // A sensor the configuration does not fuse is not among the points: judged at its default σ.
    s.training_sigma_K = sigma_K.empty() ? judged.winding_sensor_sigma_K : median(sigma_K);
    s.fit_rms_K = s.fit_points ? std::sqrt(fit2 / static_cast<double>(s.fit_points)) : 0.0;
    s.heldout_rms_K = s.heldout_points ? std::sqrt(held2 / static_cast<double>(s.heldout_points)) : 0.0;
    out.signals.push_back(s);
  }
}

/// Whether any winding signal (r̂s or a sensor) is observed on a step of the training part.
bool winding_observed_in_training(const ThermalFitResult& out) {
  return std::any_of(out.signals.begin(), out.signals.end(),
                     [](const SignalFit& s) { return s.name.rfind("winding", 0) == 0 && s.fit_points > 0; });
}

constexpr const char* kWindingUnobserved =
    "the winding is observed on no step of the training part (no winding sensor, and r_s adapts on none: the log "
    "runs at speed or without current): the network's winding follows only from the magnet node, the losses' forms "
    "and the priors, so the fused winding is a prediction this log cannot check, and its band may not hold it. Keep "
    "a winding sensor in the log, or include standstills or low speeds with current (docs/thermal.md)";

/// The steps [first, end) of session j.
struct SessionSpan {
  std::size_t first = 0, end = 0;
};
SessionSpan session_span(const ThermalRecord& r, std::size_t j) { return {r.session_first_step[j], r.session_end(j)}; }

/// The start of a session whose readings stand for the start: the magnet law's anchor and r̂s's first reading.
constexpr double kAnchorWithin_s = 300.0;

/// The steps whose magnet observations anchor the magnet law: the first kAnchorSteps with one within kAnchorWithin_s
/// of each session's start in `sessions`.
std::vector<std::size_t> anchor_steps(const ThermalRecord& r, const std::vector<std::size_t>& sessions) {
  constexpr std::size_t kAnchorSteps = 4;
  std::vector<std::size_t> steps;
  for (std::size_t j : sessions) {
    const SessionSpan span = session_span(r, j);
    std::size_t used_here = 0;
    for (std::size_t k = span.first;
         k < span.end && used_here < kAnchorSteps && r.t_s[k] - r.t_s[span.first] <= kAnchorWithin_s; ++k) {
      if (!r.steps[k].parameter[core::kPsiM].valid) continue;
      steps.push_back(k);
      ++used_here;
    }
  }
  return steps;
}

/// The copper law's reference where nothing states it (no rs_drift, no copper: {reference_C: …}; docs/thermal.md,
/// "The copper law's reference"), at the magnet anchor's steps: r̂s held there, which adapted at or before them, taken
/// as R_s at the winding sensor's reading of those steps. ψ̂m's κ term (eq. 14.10) then removes only what R_s has moved
/// since (the winding's rise), not the configured r_s's own error, which the assumed reference would read as the held
/// R_s's and move every magnet observation by (R_s 27 % low: 24 K). Where r̂s adapted on no step up to them (it is
/// still the configured start) or the sensor reads none of them, the assumed reference stands and assumed_law_notes
/// says so.
void anchor_copper_reference(io::ThermalConfig& c, const ThermalRecord& r, const std::vector<std::size_t>& steps,
                             std::vector<std::string>& notes) {
  if (steps.empty() || !r.winding_sensor) return;
  core::DriftLaw& copper = c.fusion.filter.network.copper;
  bool adapted = false;  // r̂s adapted on a step up to the last anchor step
  for (std::size_t k = 0; k <= steps.back() && !adapted; ++k) adapted = r.steps[k].parameter[core::kRs].value > 0.0;
  if (!adapted) return;
  double sum = 0.0, held_sum = 0.0, winding_sum = 0.0;
  std::size_t used = 0;
  for (const std::size_t k : steps) {
    const double held = r.steps[k].parameter[core::kPsiM].other_held, winding_C = r.steps[k].winding_sensor_C;
    if (!std::isfinite(winding_C)) continue;
    sum += held / copper.factor(winding_C);
    held_sum += held;
    winding_sum += winding_C;
    ++used;
  }
  if (used == 0) return;
  const double n = static_cast<double>(used);
  const double configured_reads_K = copper.temperature_C(held_sum / n) - winding_sum / n;
  const double configured_Ohm = copper.value_ref;
  copper.value_ref = sum / n;
  c.copper_reference_stated = true;
  char text[700];
  std::snprintf(
      text, sizeof text,
      "the copper law's reference is anchored where the magnet law's is: r_s held there (%.5g Ohm, adapted "
      "before) at the winding sensor's %.1f °C gives r_s_ref %.5g Ohm at %.4g °C; the configuration's r_s %.5g Ohm, "
      "taken at %.4g °C, read that r_s %+.1f K from the sensor. Where r_s was measured at a known "
      "temperature, say so (rs_drift, or the thermal section's copper: {reference_C: …}) and it is kept "
      "(docs/thermal.md, \"The copper law's reference\")",
      held_sum / n, winding_sum / n, copper.value_ref, copper.reference_C, configured_Ohm, copper.reference_C,
      configured_reads_K);
  notes.emplace_back(text);
}

/// The magnet law's reference from the soaked start (docs/thermal.md, "A log that does not start soaked"): the mean of
/// the first kAnchorSteps magnet observations of each session in `sessions`, each corrected for the held R_s
/// (κ·(R_s(T_w) − r̂s)), at the magnet temperatures `t_magnet_C` of those steps (the soak's, or the network's
/// prediction of the small rise since), referred to the law's reference temperature. Returns the steps used (0: none
/// within the first kAnchorWithin_s of those sessions).
std::size_t anchor_magnet_reference(io::ThermalConfig& c, const ThermalRecord& r, const std::vector<std::size_t>& sessions,
                                    const std::vector<double>& t_magnet_C, const std::vector<double>& t_winding_C,
                                    std::vector<std::string>& notes) {
  core::DriftLaw& law = c.fusion.magnet_law;
  const core::DriftLaw& copper = c.fusion.filter.network.copper;
  const std::vector<std::size_t> steps = anchor_steps(r, sessions);
  double sum = 0.0;
  for (const std::size_t k : steps) {
    const core::ParameterObservation& p = r.steps[k].parameter[core::kPsiM];
    const double psi = p.value - p.cross * (copper.at(t_winding_C[k]) - p.other_held);
    sum += psi / (1.0 + law.coeff_per_K * (t_magnet_C[k] - law.reference_C));  // ψ at the reference temperature
  }
  const std::size_t used = steps.size();
  if (used == 0) {
    notes.push_back(std::string("no magnet observation within the first 300 s") +
                    (r.session_first_step.size() > 1 ? " of a session that anchors it" : "") +
                    ": the magnet law's reference is kept as configured (" + std::to_string(law.value_ref) + " Wb at " +
                    std::to_string(law.reference_C) + " °C)");
    return 0;
  }
  law.value_ref = sum / static_cast<double>(used);
  return used;
}

/// The winding sensor's σ the soak test takes: the fused one, else kUnfusedWindingSensorSigma_K.
double soak_test_sigma_K(const core::ThermalFusionConfig& f) {
  return f.winding_sensor_sigma_K > 0.0 ? f.winding_sensor_sigma_K : kUnfusedWindingSensorSigma_K;
}

/// Whether the session starting at step `first` has a winding reading there to test its soak with.
bool soak_testable(const ThermalRecord& r, std::size_t first) {
  return r.winding_sensor && first < r.steps.size() && std::isfinite(r.steps[first].winding_sensor_C);
}

/// Whether the session starting at step `first` starts soaked, as the anchor and the open-loop start assume (every
/// node at the coolant): where it has a winding sensor, its first reading within core::kSoakBound_sigma of the
/// sensor's σ from the coolant. Returns that first reading where it does not.
std::optional<double> unsoaked_start_C(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t first) {
  if (!soak_testable(r, first)) return std::nullopt;
  const double winding_C = r.steps[first].winding_sensor_C, coolant_C = r.steps[first].load.coolant_C;
  if (core::unsoaked_excess_K(winding_C, coolant_C, soak_test_sigma_K(c.fusion)) == 0.0) return std::nullopt;
  return winding_C;
}

/// The note for sessions whose soak nothing tests (no winding reading at their start): the anchor assumes it, and a
/// warm start reads every magnet temperature cold with no sign in the band. Where r̂s adapts early, its first reading
/// (through the copper law, whose reference may itself be assumed) is said beside it, for the user to judge.
std::string untested_soak_note(const io::ThermalConfig& c, const ThermalRecord& r,
                               const std::vector<std::size_t>& untested) {
  const core::DriftLaw& copper = c.fusion.filter.network.copper;
  std::string names, readings;
  for (std::size_t j : untested) {
    const SessionSpan span = session_span(r, j);
    if (r.session_first_step.size() > 1) names += (names.empty() ? "" : ", ") + r.session_logs[j];
    for (std::size_t k = span.first; k < span.end && r.t_s[k] - r.t_s[span.first] <= kAnchorWithin_s; ++k) {
      const core::ParameterObservation& p = r.steps[k].parameter[core::kRs];
      if (!p.valid) continue;
      const double winding_C = copper.temperature_C(p.value), coolant_C = r.steps[k].load.coolant_C;
      char figures[128];
      std::snprintf(figures, sizeof figures, " puts the winding at %.1f °C, %+.1f K from the coolant, %.0f s in", winding_C,
                    winding_C - coolant_C, r.t_s[k] - r.t_s[span.first]);
      readings += (readings.empty() ? "" : "; ") + std::string("r_s's first reading") +
                  (r.session_first_step.size() > 1 ? " in " + r.session_logs[j] : std::string()) + figures;
      break;
    }
  }
  std::string note = (names.empty() ? std::string("the log has") : "the sessions " + names + " have") +
                     " no winding reading at the start: that the machine starts soaked (every node at the coolant) is "
                     "assumed, not tested, and the magnet law's reference is anchored on it. A start warmer than the "
                     "coolant (a restart on a warm machine, a log cut from a longer run) reads every magnet temperature "
                     "cold by up to the magnet's excess there, and the band does not show it";
  if (!readings.empty()) {
    note += ". " + readings + " (through the copper law's reference" +
            (c.copper_reference_stated ? std::string(")") : ", itself assumed)") +
            ": where that is more than the load since the start can have heated a soaked winding, the start was warm";
  }
  return note +
         ". Log a winding sensor, or start the log with the machine at rest and cooled "
         "(docs/thermal.md, \"A log that does not start soaked\")";
}

/// Each step's magnet and winding temperatures at its session's start (core::start_temperatures_C at its first step):
/// where the anchor takes them before a network is fitted.
void session_start_temperatures(const core::ThermalFusionConfig& f, const ThermalRecord& r, std::vector<double>& t_magnet_C,
                                std::vector<double>& t_winding_C) {
  t_magnet_C.resize(r.steps.size());
  t_winding_C.resize(r.steps.size());
  for (std::size_t j = 0; j < r.session_first_step.size(); ++j) {
    const SessionSpan span = session_span(r, j);
    const core::ThermalVec soak = core::start_temperatures_C(f, r.steps[span.first]);
    for (std::size_t k = span.first; k < span.end; ++k) {
      t_magnet_C[k] = soak[f.filter.network.magnet];
      t_winding_C[k] = soak[f.filter.network.winding];
    }
  }
}

/// Where the magnet law's reference is anchored, and in how many passes.
struct AnchorPlan {
  std::vector<std::size_t> sessions;  ///< whose first magnet observations anchor it
  bool refine = true;                 ///< a second pass at the fitted network's rise since the soak
};

/// The sessions that anchor the magnet law's reference (docs/thermal.md, "A log that does not start soaked", "A folder
/// of logs"): those that start soaked, at the soak's temperatures refined by the network's rise. Where none does, every
/// session at its winding sensor's first reading (`t_magnet_C` set so over each), in one pass, the magnet reference's σ
/// widened to the largest distance of such a reading from its coolant. Notes say which and why.
AnchorPlan plan_anchor(io::ThermalConfig& c, const ThermalRecord& r, std::vector<double>& t_magnet_C,
                       std::vector<std::string>& notes) {
  const std::size_t sessions = r.session_first_step.size();
  AnchorPlan plan;
  std::vector<std::optional<double>> unsoaked(sessions);
  std::vector<std::size_t> untested;
  std::string unsoaked_names;
  for (std::size_t j = 0; j < sessions; ++j) {
    unsoaked[j] = unsoaked_start_C(c, r, r.session_first_step[j]);
    if (!soak_testable(r, r.session_first_step[j])) untested.push_back(j);
    if (!unsoaked[j]) {
      plan.sessions.push_back(j);
    } else {
      char reading[96];
      std::snprintf(reading, sizeof reading, " (winding %.1f °C, coolant %.1f °C)", *unsoaked[j],
                    r.steps[r.session_first_step[j]].load.coolant_C);
      unsoaked_names += (unsoaked_names.empty() ? "" : ", ") + r.session_logs[j] + reading;
    }
  }
  if (!untested.empty()) notes.push_back(untested_soak_note(c, r, untested));
  if (!plan.sessions.empty()) {
    if (!unsoaked_names.empty()) {
      notes.push_back("sessions that do not start soaked (their winding sensor's first reading more than " +
                      std::to_string(static_cast<int>(core::kSoakBound_sigma)) + " σ from the coolant): " + unsoaked_names +
                      "; the magnet law's reference is anchored at the starts of the " +
                      std::to_string(plan.sessions.size()) + " that do, where the magnet is at the coolant");
    }
    return plan;
  }
  // No session starts soaked: the magnet's temperature at any start is not known.
  plan.refine = false;
  double& sigma_K = c.fusion.filter.calibration_sigma[static_cast<int>(core::Calibration::kMagnetOffset)];
  for (std::size_t j = 0; j < sessions; ++j) {
    const SessionSpan span = session_span(r, j);
    const double start_C = *unsoaked[j], coolant_C = r.steps[span.first].load.coolant_C;
    std::fill(t_magnet_C.begin() + static_cast<std::ptrdiff_t>(span.first),
              t_magnet_C.begin() + static_cast<std::ptrdiff_t>(span.end), start_C);
    sigma_K = std::max(sigma_K, std::abs(start_C - coolant_C));
    plan.sessions.push_back(j);
    char text[768];
    std::snprintf(text, sizeof text,
                  "%s does not start soaked: at its first step the winding sensor reads %.1f °C, %.1f K from the "
                  "coolant's %.1f °C (more than %.0f times the sensor's σ of %.2g K). The magnet's temperature there is "
                  "not known: the magnet law's reference is anchored at the winding's reading instead of the coolant, "
                  "and its σ (reference_sigma_K) widened to that %.1f K, so that the band holds a magnet anywhere from "
                  "the coolant to as far above the winding (a magnet left hotter than its winding by a cool-down, or "
                  "colder by a heat-up). A log that starts with the machine at rest and cooled anchors it to the "
                  "sensor's σ (docs/thermal.md, \"A log that does not start soaked\")",
                  sessions == 1 ? "the log" : ("the session " + r.session_logs[j]).c_str(), start_C, start_C - coolant_C,
                  coolant_C, core::kSoakBound_sigma, soak_test_sigma_K(c.fusion), std::abs(start_C - coolant_C));
    notes.emplace_back(text);
    if (!r.session_has_coolant(j)) {
      // The coolant was not measured but taken from thermal.coolant_C: the test cannot tell a warm start from a
      // coolant constant that is not the log's.
      std::snprintf(text, sizeof text,
                    "%s has no coolant column: the %.1f °C it is judged against is thermal.coolant_C, not a "
                    "measurement. If the machine was at rest and cooled at the start, it is that constant that is "
                    "off: set thermal.coolant_C to %.1f °C (the sensor's first reading) in --start, or log the coolant",
                    sessions == 1 ? "the log" : ("the session " + r.session_logs[j]).c_str(), coolant_C, start_C);
      notes.emplace_back(text);
    }
  }
  return plan;
}

/// The filter's noises for the fitted network: the temperatures' white noise, then the disturbances' drift, each the
/// most likely; each node's disturbance correlation time; a winding sensor's lag where none is configured.
void fit_filter_noises(const ThermalRecord& record, std::size_t training, const ThermalFitOptions& options,
                       ThermalFitResult& out) {
  out.config.fusion.filter.disturbance_W2_per_s.setZero();
  out.process_noise_K2_per_s =
      maximum_likelihood(out.config, record, training, &core::ThermalFilterConfig::process_noise_K2_per_s, -8.0, 1.0);
  out.disturbance_W2_per_s =
      maximum_likelihood(out.config, record, training, &core::ThermalFilterConfig::disturbance_W2_per_s, -6.0, 4.0);
  choose_disturbance_time_constants(out, record, training, options);
  // A winding sensor without a configured lag: its time constant, the most likely under those noises.
  if (record.winding_sensor && out.config.fusion.winding_sensor_sigma_K > 0.0 &&
      !(out.config.fusion.winding_sensor_time_constant_s > 0.0))
    fit_sensor_lag(out.config, record, training, out);
}

/// Noise alone spans 2·Φ⁻¹(0.95) = 3.29 of its σ between its 5th and 95th percentile: a signal whose span is no wider
/// shows no temperature change.
constexpr double kNoiseSpan_sigma = 3.2897072539029457;

/// The note when no parameter is identified: what the training part observed against the σ of an observation,
/// and what that means.
std::string nothing_identified(const ThermalFitResult& fit) {
  std::string spans;
  bool moves = false;
  for (const SignalFit& s : fit.signals) {
    if (s.fit_points == 0) continue;
    const double span_K = s.training_high_C - s.training_low_C;
    moves = moves || span_K > kNoiseSpan_sigma * s.training_sigma_K;
    char part[64];
    std::snprintf(part, sizeof part, " (%.2g K against a σ of %.2g K)", span_K, s.training_sigma_K);
    spans += (spans.empty() ? "" : "; ") + s.name + " " + training_span(s) + part;
  }
  if (!moves) {
    return "no parameter is identified: no temperature the training part observes moves beyond its noise (5th to "
           "95th percentile: " +
           spans +
           "). A network shows only in temperatures the losses move by many times their σ: fit it on a log that "
           "heats the machine (a longer or harder run), or start from a known network (--start)";
  }
  return "no parameter is identified although the training part's temperatures move (5th to 95th percentile: " + spans +
         "): the log determines only combinations of the parameters (\"not identifiable together\": one operating "
         "point, or a cool-down without load, shows the time constants and the losses' ratios to the conductances, "
         "not each). A log with several loads and speeds separates them; or start from a known network (--start)";
}

/// The notes on what the fitted network rests on: nothing identified, a winding never observed.
void add_closing_notes(ThermalFitResult& out) {
  if (std::none_of(out.parameters.begin(), out.parameters.end(), [](const FittedParameter& p) { return p.identified; }))
    out.notes.push_back(nothing_identified(out));
  if (!winding_observed_in_training(out)) out.notes.emplace_back(kWindingUnobserved);
}

}  // namespace

std::size_t steps_until(const ThermalRecord& r, double fit_until_s) {
  std::size_t n = 0;
  while (n < r.t_s.size() && r.t_s[n] <= fit_until_s) ++n;
  return n;
}

ThermalFitResult fit_thermal(const ThermalRecord& record, const io::ThermalConfig& start_config,
                             const ThermalFitOptions& options) {
  if (record.steps.size() < kMinFitSteps) {  // the data's fault, not the program's: exit 65, the file named
    throw io::DriveLogError(record.log, 0, 0, "",
                            "the log gives " + std::to_string(record.steps.size()) +
                                " steps of the thermal filter; a fit needs at least " + std::to_string(kMinFitSteps) +
                                " (a longer log, or a shorter period of the filter: filter.period_s, or `rpem thermal "
                                "fit --period-s`)");
  }
  ThermalFitResult out;
  const double t0 = record.t_s.front(), t_end = record.t_s.back();
  const bool default_training = std::isnan(options.fit_until_s);
  out.fit_until_s = default_training ? t0 + 0.75 * (t_end - t0) : options.fit_until_s;
  const std::size_t training = steps_until(record, out.fit_until_s);
  if (training < kMinFitSteps) {
    throw io::DriveLogError(
        record.log, 0, 0, "",
        "fewer than " + std::to_string(kMinFitSteps) + " steps of the thermal filter end by the training part's end (" +
            (default_training ? "the first 75 % of the log, to " : "--fit-until-s ") + std::to_string(out.fit_until_s) +
            " s; the log's steps end from " + std::to_string(t0) + " to " + std::to_string(t_end) + " s)");
  }
  out.training_steps = training;

  io::ThermalConfig start = start_config;
  // The magnet's reference: first at the soak temperature, then once more at the fitted network's magnet
  // temperatures of the anchor's steps (the rise since the soak), and the network fitted again.
  std::vector<double> t_magnet, t_winding;
  session_start_temperatures(start.fusion, record, t_magnet, t_winding);
  // A start that is not soaked: anchored at the winding's reading, in one pass (the network's rise since the soak
  // does not apply).
  const AnchorPlan anchor =
      options.anchor_magnet_reference ? plan_anchor(start, record, t_magnet, out.notes) : AnchorPlan{{}, false};
  // The copper law, where nothing states its reference, at the same steps, before anything reads r̂s as a temperature.
  if (options.anchor_magnet_reference && !start.copper_reference_stated)
    anchor_copper_reference(start, record, anchor_steps(record, anchor.sessions), out.notes);
  for (std::string& note : io::assumed_law_notes(start, false)) out.notes.push_back(std::move(note));
  // A winding sensor without a configured lag: τ_s from the standstills where r̂s reads the winding (eq. 14.25),
  // before the network, which then stands for the sensor's reading (eq. 14.24).
  if (record.winding_sensor && start.fusion.winding_sensor_sigma_K > 0.0 &&
      !(start.fusion.winding_sensor_time_constant_s > 0.0))
    sensor_lag_at_standstill(start, record, training, out);
  const std::vector<LossTie> ties = network::tie_collinear_losses(start, record, training, out.notes);
  const Layout layout(start, ties);
  const std::vector<double> prior = layout.values(start);
  Solved best;
  std::vector<Point> points;
  for (int pass = 0; pass < (options.anchor_magnet_reference && anchor.refine ? 2 : 1); ++pass) {
    if (options.anchor_magnet_reference)
      anchor_magnet_reference(start, record, anchor.sessions, t_magnet, t_winding, out.notes);
    points = training_points(start, record, training);
    if (points.empty()) {
      throw io::DriveLogError(record.log, 0, 0, "",
                              "the training part holds no temperature the network can be fitted to (no winding sensor, "
                              "and ψm and R_s never adapt and settle)");
    }
    const Layout pass_layout(start, ties);
    // Three starts: the topology's time constants as they are, three times shorter and three times longer.
    best = Solved{};
    for (double scale : {1.0, 1.0 / 3.0, 3.0}) {
      std::vector<double> x = prior;
      for (std::size_t k = 0; k < layout.size(); ++k) {
        if (layout.slots()[k].kind == SlotKind::kCapacitance) x[k] += std::log(scale);
      }
      Solved s = solve(pass_layout, record, training, points, prior, x, options.max_iterations);
      if (s.cost < best.cost) best = s;
    }
    const std::vector<core::ThermalVec> model = simulate_open_loop(pass_layout.apply(best.x.data()).fusion, record);
    for (std::size_t k = 0; k < model.size(); ++k) {
      t_magnet[k] = model[k][start.fusion.filter.network.magnet];
      t_winding[k] = model[k][start.fusion.filter.network.winding];
    }
  }
  const Layout fitted_layout(start, ties);
  if (!std::isfinite(best.cost) || best.cost >= kRunaway * kRunaway) {
    throw std::invalid_argument(
        "the fit did not converge to a network that follows the log (it runs away or is not "
        "finite); start it from another network (--start) or another topology (--nodes)");
  }
  out.training_cost = best.cost;
  out.config = fitted_layout.apply(best.x.data());
  intervals(fitted_layout, record, training, points, best.x, options.blocks, out);
  fit_filter_noises(record, training, options, out);
  out.coolant_drift = coolant_drift(record, training);
  out.config.fusion.filter.coolant_drift_K2_per_s = out.coolant_drift.q_K2_per_s;
  judge(out.config, record, training, points, out);
  add_closing_notes(out);
  return out;
}

}  // namespace rpem::analysis
