#include "rpem/analysis/thermal/thermal_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "rpem/analysis/cluster_robust.hpp"
#include "rpem/analysis/diagnose/effect_fit.hpp"
#include "rpem/analysis/thermal/golden_section.hpp"
#include "rpem/analysis/thermal/sensor_lag.hpp"
#include "rpem/analysis/thermal/thermal_replay.hpp"
#include "rpem/core/non_finite.hpp"

namespace rpem::analysis {
namespace {

constexpr double kZ = 1.959964;  // two-sided 95 %
using core::kInf;
/// The floor of an observation's σ in the fit's weights: temperatures are not resolved finer [K].
constexpr double kSigmaFloor_K = 0.5;
/// Each log parameter stays within e^±this of its start (a factor of 3·10⁴): finite simulations only.
constexpr double kLogRange = 10.3;
/// The prior of each logarithmic parameter: normal about the start with a standard deviation of one decade
/// (docs/thermal.md, "The fit"): it decides only where the log leaves a direction undetermined. The copper
/// loss's scale is known better: (3/2)·R_s·|i|² within a factor of 2 (AC resistance, stray load losses).
constexpr double kPriorSigmaLog = 2.302585092994046;
constexpr double kPriorSigmaLogCopper = 0.6931471805599453;
/// The range searched for the winding sensor's time constant (eq. 14.22) [s]: from below the filter's step to
/// beyond any end-winding sensor's.
constexpr double kSensorLagLow_s = 0.1, kSensorLagHigh_s = 300.0;

enum class SlotKind { kCapacitance, kToCoolant, kToCoolantAtSpeed, kBetween, kBetweenAtSpeed, kLoss, kCopperScale };

struct Slot {
  SlotKind kind;
  int i = 0, j = 0;  ///< node(s); the (first) loss form in j for kLoss
  std::string name, unit;
  /// kLoss: every form's coefficient relative to the first's (forms the log cannot tell apart move together).
  std::array<double, core::kLossForms> share{};
};

/// Loss forms at one node that the training part cannot tell apart, fitted as one (thermal_fit.hpp).
struct LossTie {
  int node;
  std::vector<int> forms;
  std::vector<double> share;  ///< coefficients relative to the first form's
};

/// Where each fitted quantity lives in the network, and how the parameter vector maps onto a configuration.
class Layout {
 public:
  Layout(const io::ThermalConfig& start, const std::vector<LossTie>& ties) : start_(start) {
    const core::ThermalNetwork& n = start.fusion.filter.network;
    auto name = [&](int i) { return start.node_names[static_cast<std::size_t>(i)]; };
    for (int i = 0; i < n.nodes; ++i) slots_.push_back({SlotKind::kCapacitance, i, 0, "C " + name(i), "J/K"});
    slots_.push_back({SlotKind::kCopperScale, n.winding, 0, "copper loss scale", "1"});
    for (int i = 0; i < n.nodes; ++i) {
      if (n.to_coolant_W_per_K[i] > 0.0) slots_.push_back({SlotKind::kToCoolant, i, 0, "G " + name(i) + "–coolant", "W/K"});
      if (n.to_coolant_at_base_speed_W_per_K[i] > 0.0)
        slots_.push_back({SlotKind::kToCoolantAtSpeed, i, 0, "G " + name(i) + "–coolant at base speed (eq. 14.1b)", "W/K"});
    }
    for (int i = 0; i < n.nodes; ++i) {
      for (int j = i + 1; j < n.nodes; ++j) {
        if (n.between_W_per_K(i, j) > 0.0)
          slots_.push_back({SlotKind::kBetween, i, j, "G " + name(i) + "–" + name(j), "W/K"});
        if (n.between_W_per_K(i, j) > 0.0 && n.between_at_base_speed_W_per_K(i, j) > 0.0)
          slots_.push_back(
              {SlotKind::kBetweenAtSpeed, i, j, "G " + name(i) + "–" + name(j) + " at base speed (eq. 14.1b)", "W/K"});
      }
    }
    const auto& forms = core::loss_forms();
    for (int i = 0; i < n.nodes; ++i) {
      std::array<bool, core::kLossForms> done{};
      for (const LossTie& t : ties) {
        if (t.node != i) continue;
        Slot s{SlotKind::kLoss, i, t.forms.front(), "", "W", {}};
        for (std::size_t k = 0; k < t.forms.size(); ++k) {
          s.share[static_cast<std::size_t>(t.forms[k])] = t.share[k];
          s.name += (k ? "+" : "") + std::string(forms[static_cast<std::size_t>(t.forms[k])].name);
          done[static_cast<std::size_t>(t.forms[k])] = true;
        }
        s.name += " at " + name(i);
        slots_.push_back(s);
      }
      for (int f = 0; f < core::kLossForms; ++f) {
        if (done[static_cast<std::size_t>(f)] || n.loss_at_base_W(f, i) <= 0.0) continue;
        Slot s{SlotKind::kLoss, i, f, std::string(forms[static_cast<std::size_t>(f)].name) + " at " + name(i), "W", {}};
        s.share[static_cast<std::size_t>(f)] = 1.0;
        slots_.push_back(s);
      }
    }
  }

  [[nodiscard]] const std::vector<Slot>& slots() const { return slots_; }
  [[nodiscard]] std::size_t size() const { return slots_.size(); }

  /// The parameter vector of a configuration (log values).
  [[nodiscard]] std::vector<double> values(const io::ThermalConfig& c) const {
    std::vector<double> x;
    for (const Slot& s : slots_) x.push_back(std::log(quantity(c, s)));
    return x;
  }

  [[nodiscard]] io::ThermalConfig apply(const double* x) const {
    io::ThermalConfig c = start_;
    core::ThermalNetwork& n = c.fusion.filter.network;
    for (std::size_t k = 0; k < slots_.size(); ++k) {
      const Slot& s = slots_[k];
      const double v = std::exp(x[k]);
      switch (s.kind) {
        case SlotKind::kCapacitance:
          n.capacitance_J_per_K[s.i] = v;
          break;
        case SlotKind::kCopperScale:
          n.copper_scale = v;
          break;
        case SlotKind::kToCoolant:
          n.to_coolant_W_per_K[s.i] = v;
          break;
        case SlotKind::kToCoolantAtSpeed:
          n.to_coolant_at_base_speed_W_per_K[s.i] = v;
          break;
        case SlotKind::kBetween:
          n.between_W_per_K(s.i, s.j) = n.between_W_per_K(s.j, s.i) = v;
          break;
        case SlotKind::kBetweenAtSpeed:
          n.between_at_base_speed_W_per_K(s.i, s.j) = n.between_at_base_speed_W_per_K(s.j, s.i) = v;
          break;
        case SlotKind::kLoss:
          for (int f = 0; f < core::kLossForms; ++f) {
            if (s.share[static_cast<std::size_t>(f)] > 0.0)
              n.loss_at_base_W(f, s.i) = v * s.share[static_cast<std::size_t>(f)];
          }
          break;
      }
    }
    return c;
  }

  /// A slot's value in a configuration (SI).
  [[nodiscard]] static double quantity(const io::ThermalConfig& c, const Slot& s) {
    const core::ThermalNetwork& n = c.fusion.filter.network;
    switch (s.kind) {
      case SlotKind::kCapacitance:
        return n.capacitance_J_per_K[s.i];
      case SlotKind::kCopperScale:
        return n.copper_scale;
      case SlotKind::kToCoolant:
        return n.to_coolant_W_per_K[s.i];
      case SlotKind::kToCoolantAtSpeed:
        return n.to_coolant_at_base_speed_W_per_K[s.i];
      case SlotKind::kBetween:
        return n.between_W_per_K(s.i, s.j);
      case SlotKind::kBetweenAtSpeed:
        return n.between_at_base_speed_W_per_K(s.i, s.j);
      case SlotKind::kLoss:
        return n.loss_at_base_W(s.j, s.i);  // the first form's
    }
    return 0.0;
  }

 private:
  io::ThermalConfig start_;
  std::vector<Slot> slots_;
};

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
  core::ThermalVec t = soaked_start(f, r);
  core::SensorLag lag;
  std::size_t p = 0;
  for (std::size_t k = 0; k < steps && p < points.size(); ++k) {
    const core::ThermalStepData& s = r.steps[k];
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

/// The median of a form's basis over the training part's steps with a load.
double median_basis(const ThermalRecord& r, std::size_t steps, int form) {
  std::vector<double> b;
  for (std::size_t k = 0; k < steps; ++k) {
    const double v = r.steps[k].load.basis[static_cast<std::size_t>(form)];
    if (v > 0.0) b.push_back(v);
  }
  if (b.empty()) return 0.0;
  std::nth_element(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(b.size() / 2), b.end());
  return b[b.size() / 2];
}

/// Loss forms at one node that the training part cannot tell apart — the ratio of their bases constant to
/// 2 % between its 10th and 90th percentiles (one operating point; one speed for hysteresis against eddy
/// currents) — are tied: fitted as one, each carrying an equal part of their loss at the training part's
/// median operating point (docs/thermal.md, "What one log cannot tell"). Sets the start's coefficients so.
std::vector<LossTie> tie_collinear_losses(io::ThermalConfig& c, const ThermalRecord& r, std::size_t steps,
                                          std::vector<std::string>& notes) {
  core::ThermalNetwork& n = c.fusion.filter.network;
  const auto& forms = core::loss_forms();
  auto collinear = [&](int f, int g) {
    std::vector<double> ratio;
    double largest = 0.0;
    for (std::size_t k = 0; k < steps; ++k) largest = std::max(largest, r.steps[k].load.basis[static_cast<std::size_t>(f)]);
    for (std::size_t k = 0; k < steps; ++k) {
      const auto& b = r.steps[k].load.basis;
      if (b[static_cast<std::size_t>(f)] > 1e-3 * largest)
        ratio.push_back(b[static_cast<std::size_t>(g)] / b[static_cast<std::size_t>(f)]);
    }
    if (ratio.size() < 3) return false;
    std::sort(ratio.begin(), ratio.end());
    const double p10 = ratio[ratio.size() / 10], p90 = ratio[ratio.size() * 9 / 10], mid = ratio[ratio.size() / 2];
    return mid > 0.0 && (p90 - p10) / mid < 0.02;
  };
  std::vector<LossTie> ties;
  for (int i = 0; i < n.nodes; ++i) {
    std::array<bool, core::kLossForms> used{};
    for (int f = 0; f < core::kLossForms; ++f) {
      if (used[static_cast<std::size_t>(f)] || n.loss_at_base_W(f, i) <= 0.0) continue;
      LossTie t{i, {f}, {1.0}};
      for (int g = f + 1; g < core::kLossForms; ++g) {
        if (!used[static_cast<std::size_t>(g)] && n.loss_at_base_W(g, i) > 0.0 && collinear(f, g)) {
          t.forms.push_back(g);
          used[static_cast<std::size_t>(g)] = true;
        }
      }
      if (t.forms.size() < 2) continue;
      double total = 0.0;
      std::string names;
      for (int g : t.forms) {
        total += n.loss_at_base_W(g, i) * median_basis(r, steps, g);
        names += (names.empty() ? "" : ", ") + std::string(forms[static_cast<std::size_t>(g)].name);
      }
      const double each = total / static_cast<double>(t.forms.size());
      for (int g : t.forms) n.loss_at_base_W(g, i) = each / std::max(median_basis(r, steps, g), 1e-12);
      t.share.clear();
      for (int g : t.forms) t.share.push_back(n.loss_at_base_W(g, i) / n.loss_at_base_W(f, i));
      notes.push_back(names + " at " + c.node_names[static_cast<std::size_t>(i)] +
                      " cannot be told apart on the training part (their bases keep one ratio): fitted as one loss, "
                      "each an equal part of it at the training part's median operating point");
      ties.push_back(t);
    }
  }
  return ties;
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
  const Eigen::VectorXd& unexcited = cov.unexcited;
  const io::ThermalConfig fitted = layout.apply(x.data());
  for (std::size_t k = 0; k < layout.size(); ++k) {
    const Slot& s = layout.slots()[k];
    const auto kk = static_cast<Eigen::Index>(k);
    FittedParameter p;
    p.name = s.name;
    p.unit = s.unit;
    p.value = Layout::quantity(fitted, s);
    const bool excited = unexcited[kk] < 0.5;
    auto rel = [&](double variance) {
      if (!excited) return kInf;
      const double half = kZ * std::sqrt(std::max(variance, 0.0));
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

/// RMS of the network's misses on each observed signal, training and held out.
void judge(const io::ThermalConfig& c, const ThermalRecord& r, std::size_t training, ThermalFitResult& out) {
  const core::ThermalFusionConfig& f = c.fusion;
  out.open_loop_C = simulate_open_loop(f, r);
  const char* names[3] = {"magnet (from psi_m)", "winding (from r_s)", "winding sensor"};
  // The sensor is judged on every step that has one, whether or not the configuration fuses it.
  core::ThermalFusionConfig judged = f;
  if (judged.winding_sensor_sigma_K <= 0.0) judged.winding_sensor_sigma_K = 1.0;
  std::vector<core::SensorLag> lag(r.steps.size());  // at each step's start
  for (std::size_t k = 0; k + 1 < r.steps.size(); ++k) {
    lag[k + 1] = lag[k];
    advance_sensor_lag(judged, r.steps[k], core::thermal_rates(f.filter.network, r.steps[k].load), out.open_loop_C[k],
                       lag[k + 1]);
  }
  for (int kind = 0; kind < 3; ++kind) {
    SignalFit s;
    s.name = names[kind];
    double fit2 = 0.0, held2 = 0.0;
    for (std::size_t k = 0; k < r.steps.size(); ++k) {
      const core::StepObservations o =
          core::step_observations(judged, r.steps[k], out.open_loop_C[k], core::ThermalVec::Zero(), lag[k]);
      if (!o.present[static_cast<std::size_t>(kind)]) continue;
      const double m = miss_K(o, kind, out.open_loop_C[k], own_node(f.filter.network, kind));
      if (k < training) {
        fit2 += m * m;
        ++s.fit_points;
      } else {
        held2 += m * m;
        ++s.heldout_points;
        s.heldout_worst_K = std::max(s.heldout_worst_K, std::abs(m));
      }
    }
    if (s.fit_points + s.heldout_points == 0) continue;
    s.fit_rms_K = s.fit_points ? std::sqrt(fit2 / static_cast<double>(s.fit_points)) : 0.0;
    s.heldout_rms_K = s.heldout_points ? std::sqrt(held2 / static_cast<double>(s.heldout_points)) : 0.0;
    out.signals.push_back(s);
  }
}

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
    const core::ParameterObservation& p = r.steps[k].parameter[rs];
    const double sensor = r.steps[k].winding_sensor_C;
    if (!p.valid || !std::isfinite(sensor) || !(p.time_constant_s >= 0.0)) {
      close();
      continue;
    }
    run.t_rs_C.push_back(copper.temperature_C(p.value));
    run.sensor_C.push_back(sensor);
    run.tau_r_s.push_back(p.time_constant_s);
    run.dt_s.push_back(r.steps[k].load.dt_s);
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
                      std::to_string(e.lower_s) + ", " + std::to_string(e.upper_s) + "] s; " +
                      (used ? "used, the winding node standing for the sensor's reading (eq. 14.24)"
                            : "not used (fewer than three runs, or no lag within the interval)"));
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

/// The magnet law's reference from the soaked start (docs/thermal.md, "The magnet's reference"): the mean of
/// the first kAnchorSteps magnet observations, each corrected for the held R_s (κ·(R_s(T_w) − r̂s)), at the
/// magnet temperatures `t_magnet_C` of those steps (the soak's, or the network's prediction of the small rise
/// since), referred to the law's reference temperature. Returns the steps used (0: none within the first
/// kAnchorWithin_s).
std::size_t anchor_magnet_reference(io::ThermalConfig& c, const ThermalRecord& r, const std::vector<double>& t_magnet_C,
                                    const std::vector<double>& t_winding_C, std::vector<std::string>& notes) {
  constexpr std::size_t kAnchorSteps = 4;
  constexpr double kAnchorWithin_s = 300.0;
  core::DriftLaw& law = c.fusion.magnet_law;
  const core::DriftLaw& copper = c.fusion.filter.network.copper;
  double sum = 0.0;
  std::size_t used = 0;
  for (std::size_t k = 0; k < r.steps.size() && used < kAnchorSteps && r.t_s[k] - r.t_s.front() <= kAnchorWithin_s; ++k) {
    const core::ParameterObservation& p = r.steps[k].parameter[core::kPsiM];
    if (!p.valid) continue;
    const double psi = p.value - p.cross * (copper.at(t_winding_C[k]) - p.other_held);
    sum += psi / (1.0 + law.coeff_per_K * (t_magnet_C[k] - law.reference_C));  // ψ at the reference temperature
    ++used;
  }
  if (used == 0) {
    notes.push_back("no magnet observation within the first 300 s: the magnet law's reference is kept as configured (" +
                    std::to_string(law.value_ref) + " Wb at " + std::to_string(law.reference_C) + " °C)");
    return 0;
  }
  law.value_ref = sum / static_cast<double>(used);
  return used;
}

}  // namespace

io::ThermalConfig default_topology(const io::ThermalConfig& laws, const ThermalRecord& r, int nodes) {
  io::ThermalConfig c = laws;
  core::ThermalNetwork& n = c.fusion.filter.network;
  // Scales from the record: the mean copper loss at the reference resistance and a temperature rise.
  double i2 = 0.0, iron = 0.0, magnet_eddy = 0.0, i2_max = 0.0;
  for (const core::ThermalStepData& s : r.steps) {
    i2 += s.load.current_sq_A2;
    i2_max = std::max(i2_max, s.load.current_sq_A2);
    iron += s.load.basis[static_cast<std::size_t>(core::LossForm::kIronEddy)];
    magnet_eddy += s.load.basis[static_cast<std::size_t>(core::LossForm::kMagnetEddy)];
  }
  const double count = std::max<double>(1.0, static_cast<double>(r.steps.size()));
  const double copper_W = std::max(1.5 * n.copper.value_ref * i2 / count, 1.0);
  const double iron_basis = std::max(iron / count, 1e-3);
  const double magnet_basis = std::max(magnet_eddy / count, 1e-3);
  const double rise_K = 60.0;  // a machine near its rating
  // The winding's conductance: the mean copper loss over a typical rise, at least three times the copper loss's
  // own growth with temperature at the largest current ((3/2)·R_ref·α·i²_max: below it the network runs away).
  const double feedback_W_per_K = 1.5 * n.copper.value_ref * n.copper.coeff_per_K * i2_max;
  const double g_W_per_K = std::max(copper_W / rise_K, 3.0 * feedback_W_per_K);
  n.nodes = nodes;
  n.between_W_per_K.setZero();
  n.between_at_base_speed_W_per_K.setZero();
  n.loss_at_base_W.setZero();
  n.to_coolant_W_per_K.setZero();
  n.to_coolant_at_base_speed_W_per_K.setZero();
  n.capacitance_J_per_K.setOnes();
  c.node_names = {};
  c.fusion.filter.process_noise_K2_per_s.setZero();
  const int eddy = static_cast<int>(core::LossForm::kIronEddy), hyst = static_cast<int>(core::LossForm::kIronHysteresis);
  const int magnet = static_cast<int>(core::LossForm::kMagnetEddy);
  if (nodes == 2) {
    // winding (with the stator), magnet (with the rotor)
    c.node_names[0] = "winding", c.node_names[1] = "magnet";
    n.winding = 0, n.magnet = 1;
    n.to_coolant_W_per_K << g_W_per_K, 0.2 * g_W_per_K, 0, 0;
    n.to_coolant_at_base_speed_W_per_K[1] = 0.2 * g_W_per_K;  // the rotor's convection (eq. 14.1b)
    n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 0.15 * g_W_per_K;
    n.between_at_base_speed_W_per_K(0, 1) = n.between_at_base_speed_W_per_K(1, 0) = 0.15 * g_W_per_K;  // the air gap
    n.capacitance_J_per_K << 300.0 * g_W_per_K, 1500.0 * 0.5 * g_W_per_K, 1, 1;
    n.loss_at_base_W(hyst, 0) = n.loss_at_base_W(eddy, 0) = 0.1 * copper_W / iron_basis;
    n.loss_at_base_W(eddy, 1) = 0.05 * copper_W / iron_basis;
    n.loss_at_base_W(magnet, 1) = 0.05 * copper_W / magnet_basis;
  } else {
    // winding, stator iron (teeth and yoke, on the cooling jacket), magnet (with the rotor)
    c.node_names[0] = "winding", c.node_names[1] = "stator_iron", c.node_names[2] = "magnet";
    n.winding = 0, n.magnet = 2;
    n.to_coolant_W_per_K << 0.1 * g_W_per_K, 2.0 * g_W_per_K, 0.1 * g_W_per_K, 0;
    n.to_coolant_at_base_speed_W_per_K[2] = 0.1 * g_W_per_K;  // the rotor's convection (eq. 14.1b)
    n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 1.5 * g_W_per_K;
    n.between_W_per_K(1, 2) = n.between_W_per_K(2, 1) = 0.15 * g_W_per_K;
    n.between_at_base_speed_W_per_K(1, 2) = n.between_at_base_speed_W_per_K(2, 1) = 0.15 * g_W_per_K;  // the air gap
    n.capacitance_J_per_K << 100.0 * g_W_per_K, 600.0 * g_W_per_K, 1500.0 * 0.4 * g_W_per_K, 1;
    n.loss_at_base_W(hyst, 1) = n.loss_at_base_W(eddy, 1) = 0.1 * copper_W / iron_basis;
    n.loss_at_base_W(eddy, 2) = 0.05 * copper_W / iron_basis;
    n.loss_at_base_W(magnet, 2) = 0.05 * copper_W / magnet_basis;
  }
  return c;
}

/// The disturbances' correlation times τ_d (eq. 14.19) jointly with q_d, by the training part's innovation
/// likelihood. On a log-spaced grid (half decades from 300 s to 10⁵ s, beside the walk) q_d is refitted at each
/// τ_d and the pair of the highest likelihood kept. A grid, not a search: the likelihood in τ_d is flat towards
/// the walk and need not be unimodal, and six points bracket the network's time constants (minutes) to a log's
/// length (hours). Per node, each in turn (winding first, the others held at their choice so far): the nodes'
/// disturbances have different causes (docs/thermal.md, "A Gauss–Markov disturbance": one τ_d for the network
/// let the magnet's choice decide the winding's). A given τ_d is every node's.
/// The walk is the nested model (τ_d → ∞), so a finite τ_d is one more parameter: 2·ΔlnL > χ²₁(1 − 0.05/m) = z²,
/// z the normal quantile at 1 − 0.05/(2m) (eq. 14.21a), found by bisection on erfc in [0, 10].
double likelihood_ratio_threshold(std::size_t trials) {
  constexpr double kAlpha = 0.05;  // the fit's 95 % intervals' level
  const double tail = kAlpha / static_cast<double>(std::max<std::size_t>(trials, 1));
  double lo = 0.0, hi = 10.0;
  for (int k = 0; k < 100; ++k) {
    const double z = 0.5 * (lo + hi);
    (std::erfc(z / std::sqrt(2.0)) > tail ? lo : hi) = z;  // erfc(z/√2): two-sided tail of the normal
  }
  return 0.5 * lo * lo;
}

void choose_disturbance_time_constants(ThermalFitResult& out, const ThermalRecord& record, std::size_t training,
                                       const ThermalFitOptions& options) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
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

ThermalFitResult fit_thermal(const ThermalRecord& record, const io::ThermalConfig& start_config,
                             const ThermalFitOptions& options) {
  if (record.steps.size() < 10) {
    throw std::invalid_argument(
        "the log gives " + std::to_string(record.steps.size()) +
        " steps of the thermal filter; a fit needs at least 10 (a longer log, or a shorter filter.period_s)");
  }
  ThermalFitResult out;
  const double t0 = record.t_s.front(), t_end = record.t_s.back();
  out.fit_until_s = std::isnan(options.fit_until_s) ? t0 + 0.75 * (t_end - t0) : options.fit_until_s;
  std::size_t training = 0;
  while (training < record.steps.size() && record.t_s[training] <= out.fit_until_s) ++training;
  if (training < 10) throw std::invalid_argument("fewer than 10 steps end before fit_until_s");
  out.training_steps = training;

  io::ThermalConfig start = start_config;
  // A winding sensor without a configured lag: τ_s from the standstills where r̂s reads the winding (eq. 14.25),
  // before the network, which then stands for the sensor's reading (eq. 14.24).
  if (record.winding_sensor && start.fusion.winding_sensor_sigma_K > 0.0 &&
      !(start.fusion.winding_sensor_time_constant_s > 0.0))
    sensor_lag_at_standstill(start, record, training, out);
  const std::vector<LossTie> ties = tie_collinear_losses(start, record, training, out.notes);
  const Layout layout(start, ties);
  const std::vector<double> prior = layout.values(start);
  // The magnet's reference: first at the soak temperature, then once more at the fitted network's magnet
  // temperatures of the anchor's steps (the rise since the soak), and the network fitted again.
  const core::ThermalVec soak = soaked_start(start.fusion, record);
  std::vector<double> t_magnet(record.steps.size(), soak[start.fusion.filter.network.magnet]);
  std::vector<double> t_winding(record.steps.size(), soak[start.fusion.filter.network.winding]);
  Solved best;
  std::vector<Point> points;
  for (int pass = 0; pass < (options.anchor_magnet_reference ? 2 : 1); ++pass) {
    if (options.anchor_magnet_reference) anchor_magnet_reference(start, record, t_magnet, t_winding, out.notes);
    points = training_points(start, record, training);
    if (points.empty()) {
      throw std::invalid_argument(
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
  // The filter's noise: the temperatures' white noise, then the disturbances' drift, each the most likely.
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
  judge(out.config, record, training, out);
  return out;
}

}  // namespace rpem::analysis
