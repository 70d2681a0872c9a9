#include "rpem/analysis/diagnose/effect_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "rpem/analysis/cluster_robust.hpp"

namespace rpem::analysis {
namespace {

/// Forward-difference step on the scaled parameters (1 = a typical magnitude).
constexpr double kStep = 1e-3;

/// Where the fit's parameters live: the free calibrated constants, then each effect's block.
struct Layout {
  std::vector<std::size_t> free;  ///< indices into kCalibrated
};

/// The replay as a Ceres cost: the free calibrated constants (one block, if any) and one block per
/// effect; the training residuals as residuals.
class ReplayCost {
 public:
  ReplayCost(const EffectFitter& fitter, const EffectSet& start, Layout layout)
      : fitter_(fitter), start_(start), layout_(std::move(layout)) {}

  bool operator()(double const* const* parameters, double* residuals) const {
    EffectSet set = start_;
    std::size_t block = 0;
    if (!layout_.free.empty()) {
      for (std::size_t j = 0; j < layout_.free.size(); ++j) set.calibration[layout_.free[j]] = parameters[0][j];
      block = 1;
    }
    for (std::size_t j = 0; j < set.effects.size(); ++j, ++block) {
      const int n = set.effects[j].row->parameters;
      set.parameters[j].assign(parameters[block], parameters[block] + n);
    }
    fitter_.training_residuals(set, buffer_);
    std::copy(buffer_.begin(), buffer_.end(), residuals);
    return true;
  }

 private:
  const EffectFitter& fitter_;
  EffectSet start_;
  Layout layout_;
  mutable std::vector<double> buffer_;
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

/// The Gauss–Newton parameter change δ = −(JᵀJ)⁻¹·Jᵀr that minimises |r + J·δ|² (a tiny ridge keeps
/// columns that vanish at the start harmless).
Eigen::VectorXd gauss_newton_step(const std::vector<std::vector<double>>& columns, const std::vector<double>& r) {
  const auto n = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd h(n, n);
  Eigen::VectorXd g(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    g[i] = dot(columns[static_cast<std::size_t>(i)], r);
    for (Eigen::Index j = 0; j <= i; ++j) h(i, j) = h(j, i) = dot(columns[static_cast<std::size_t>(i)], columns[static_cast<std::size_t>(j)]);
  }
  const double ridge = 1e-9 * std::max(h.trace(), 1e-300);
  h.diagonal().array() += ridge;
  return -h.ldlt().solve(g);
}

/// SSR(r + J·δ) − SSR(r), the change a parameter change δ makes in the linearisation: 2δᵀJᵀr + δᵀJᵀJδ.
double step_change(const std::vector<std::vector<double>>& columns, const std::vector<double>& r, const Eigen::VectorXd& delta) {
  std::vector<double> jd(r.size(), 0.0);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    for (std::size_t i = 0; i < r.size(); ++i) jd[i] += columns[c][i] * delta[static_cast<Eigen::Index>(c)];
  }
  return 2.0 * dot(jd, r) + dot(jd, jd);
}

/// The Gauss–Newton step with the candidate's parameters (columns from `first` on) kept within their
/// bounds on the change: a parameter whose step would leave them is held at the bound and the rest
/// re-solved (an active set; a candidate has at most a few parameters).
template <class Bounds>
Eigen::VectorXd bounded_step(const std::vector<std::vector<double>>& columns, const std::vector<double>& r, std::size_t first,
                             const Bounds& bounds) {
  const std::size_t n = columns.size();
  std::vector<bool> held(n, false);
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  for (std::size_t pass = 0; pass <= n - first; ++pass) {
    // Residual after the held changes; solve for the free ones.
    std::vector<double> shifted = r;
    std::vector<std::vector<double>> free_columns;
    std::vector<std::size_t> free_index;
    for (std::size_t c = 0; c < n; ++c) {
      if (held[c]) {
        for (std::size_t i = 0; i < r.size(); ++i) shifted[i] += columns[c][i] * delta[static_cast<Eigen::Index>(c)];
      } else {
        free_columns.push_back(columns[c]);
        free_index.push_back(c);
      }
    }
    const Eigen::VectorXd step = free_columns.empty() ? Eigen::VectorXd() : gauss_newton_step(free_columns, shifted);
    bool violated = false;
    for (std::size_t j = 0; j < free_index.size(); ++j) {
      const std::size_t c = free_index[j];
      delta[static_cast<Eigen::Index>(c)] = step[static_cast<Eigen::Index>(j)];
      if (c < first) continue;
      const auto [lo, hi] = bounds(static_cast<int>(c - first));
      const double v = delta[static_cast<Eigen::Index>(c)];
      if (v < lo || v > hi) {
        delta[static_cast<Eigen::Index>(c)] = std::clamp(v, lo, hi);
        held[c] = true;
        violated = true;
      }
    }
    if (!violated) break;
  }
  return delta;
}

// The bounds of fit()'s parameter blocks: the calibrated constants' block first (when any is free), then
// one block per effect, in the order blocks holds them.
void bound_parameters(ceres::Problem& problem, const std::vector<double*>& blocks, std::size_t free_calibrated,
                      const EffectSet& set, const EffectContext& context) {
  std::size_t block = 0;
  if (free_calibrated > 0) {
    for (std::size_t j = 0; j < free_calibrated; ++j) {
      problem.SetParameterLowerBound(blocks[0], static_cast<int>(j), -kCalibrationBound);
      problem.SetParameterUpperBound(blocks[0], static_cast<int>(j), kCalibrationBound);
    }
    block = 1;
  }
  for (std::size_t j = 0; j < set.effects.size(); ++j, ++block) {
    for (int i = 0; i < set.effects[j].row->parameters; ++i) {
      const auto [lo, hi] = parameter_bounds(set.effects[j], context, i);
      if (std::isfinite(lo)) problem.SetParameterLowerBound(blocks[block], i, lo);
      if (std::isfinite(hi)) problem.SetParameterUpperBound(blocks[block], i, hi);
    }
  }
}

ceres::Solver::Options fit_options() {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  options.function_tolerance = 1e-5;  // relative: far below what the held-out test resolves
  options.parameter_tolerance = 1e-6;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  // With bounds, each accepted trust-region step is followed by Ceres' projected Armijo line search; its
  // default cubic interpolation evaluates the gradient at every trial step — here a numeric Jacobian, one
  // replay per parameter. The search is switched off (zero step-size iterations: the trust region alone
  // keeps the step inside the bounds); were it on, quadratic interpolation would ask for the cost alone
  // (docs/benchmarks.md, rpem diagnose).
  options.line_search_interpolation_type = ceres::QUADRATIC;
  options.max_num_line_search_step_size_iterations = 0;
  return options;
}

}  // namespace

bool identified(const EffectSet& set, const CalibrationIntervals& ci, std::size_t i) {
  return ci.half_width[i] <= kIdentifiedHalfWidth && std::abs(set.calibration[i]) < 0.99 * kCalibrationBound;
}

double misfit_norm_A(std::size_t training_samples, double heldout_rms_A, double noise_floor_A) {
  if (heldout_rms_A <= noise_floor_A) return 0.0;
  return std::sqrt(static_cast<double>(training_samples) * (heldout_rms_A * heldout_rms_A - noise_floor_A * noise_floor_A));
}

Identification identification(const EffectSet& set, const CalibrationIntervals& ci, std::size_t i, double misfit_A) {
  if (identified(set, ci, i)) return Identification::kNarrow;
  if (!(std::abs(set.calibration[i]) < 0.99 * kCalibrationBound)) return Identification::kNot;
  // The configured value θ_c outside θ̂·(1 ± (h + m)), with θ̂ = θ_c·(1 + s·δ): |s·δ| > (h + m)·(1 + s·δ).
  const double moved = kCalibrationScale * set.calibration[i];
  const double widened = ci.half_width[i] + ci.change_per_A[i] * misfit_A;
  return std::abs(moved) > widened * (1.0 + moved) ? Identification::kRejectsConfiguration : Identification::kNot;
}

ExtendedModel EffectSet::model(const EffectContext& c) const {
  ExtendedModel m = c.base;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    m.machine.*kCalibratedFields[i] *= 1.0 + kCalibrationScale * calibration[i];
  }
  for (std::size_t j = 0; j < effects.size(); ++j) effects[j].row->apply(effects[j], parameters[j].data(), c, m);
  return m;
}

EffectSet EffectSet::with(const Effect& e, const EffectContext&, const std::vector<double>& start) const {
  EffectSet s = *this;
  if (e.row->fitted_constant() >= 0) s.calibrated[static_cast<std::size_t>(e.row->fitted_constant())] = true;
  s.effects.push_back(e);
  s.parameters.push_back(start.empty() ? std::vector<double>(static_cast<std::size_t>(e.row->parameters), 0.0) : start);
  return s;
}

EffectSet EffectSet::without(const Effect& e) const {
  EffectSet s = *this;
  s.effects.clear();
  s.parameters.clear();
  for (std::size_t j = 0; j < effects.size(); ++j) {
    if (effects[j] == e) continue;
    s.effects.push_back(effects[j]);
    s.parameters.push_back(parameters[j]);
  }
  return s;
}

bool EffectSet::contains(const Effect& e) const { return std::find(effects.begin(), effects.end(), e) != effects.end(); }

int EffectSet::free_calibration() const {
  return static_cast<int>(std::count(calibrated.begin(), calibrated.end(), true));
}

double BlockScores::total() const {
  double t = 0.0;
  for (double s : ssr) t += s;
  return t;
}

EffectFitter::EffectFitter(const ModelReplay& replay, const EffectContext& context) : replay_(replay), context_(context) {
  ReplayOutput baseline;
  replay_.run(context_.base, baseline, Blocks::kTraining);
  const LogData& log = replay_.log();
  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (log.training(k) && baseline.valid[k]) training_.push_back(k);
  }
}

EffectFitter EffectFitter::with_loss(const RobustLoss& loss) const {
  EffectFitter f = *this;
  f.loss_ = loss;
  return f;
}

void EffectFitter::training_residuals(const EffectSet& set, std::vector<double>& out) const {
  ReplayOutput r;
  replay_.run(set.model(context_), r, Blocks::kTraining);
  out.resize(2 * training_.size());
  for (std::size_t j = 0; j < training_.size(); ++j) {
    const std::size_t k = training_[j];
    // A sample that stops being valid (non-finite) counts as a large miss rather than vanishing.
    core::Vec2 e = r.valid[k] ? r.residual_A[k] : core::Vec2::Constant(1e3);
    e *= loss_.residual_scale(e.squaredNorm());
    out[2 * j] = e[0];
    out[2 * j + 1] = e[1];
  }
}

double EffectFitter::training_ssr(const EffectSet& set) const {
  std::vector<double> r;
  training_residuals(set, r);
  return dot(r, r);
}

BlockScores EffectFitter::heldout(const EffectSet& set) const {
  ReplayOutput r;
  replay_.run(set.model(context_), r, Blocks::kHeldout);
  const LogData& log = replay_.log();
  BlockScores b;
  b.ssr.assign(static_cast<std::size_t>(log.blocks / 2), 0.0);
  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (!log.heldout(k) || !r.valid[k]) continue;
    b.ssr[static_cast<std::size_t>(log.block[k] / 2)] += loss_.rho(r.residual_A[k].squaredNorm());
    ++b.samples;
  }
  return b;
}

std::vector<double> EffectFitter::column(const EffectSet& moved, const std::vector<double>& r0, double h) const {
  std::vector<double> r;
  training_residuals(moved, r);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = (r[i] - r0[i]) / h;
  return r;
}

ScreenBasis EffectFitter::screen_basis(const EffectSet& base) const {
  ScreenBasis b;
  training_residuals(base, b.r0);
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (!base.calibrated[i]) continue;
    EffectSet moved = base;
    moved.calibration[i] += kStep;
    b.columns.push_back(column(moved, b.r0, kStep));
  }
  // The effects already in the model move with the candidate too: an effect fitted without the one still
  // missing has taken part of its residual (a dead time fitted without the command delay), and a screening
  // that held it fixed would credit the missing effect with only what is left (a parameter its bounds pin,
  // width below kStep, stays where it is).
  for (std::size_t j = 0; j < base.effects.size(); ++j) {
    for (std::size_t i = 0; i < base.parameters[j].size(); ++i) {
      const auto [lo, hi] = parameter_bounds(base.effects[j], context_, static_cast<int>(i));
      if (hi - lo < kStep) continue;
      EffectSet moved = base;
      const double h = hi >= base.parameters[j][i] + kStep ? kStep : -kStep;
      moved.parameters[j][i] += h;
      b.columns.push_back(column(moved, b.r0, h));
    }
  }
  if (!b.columns.empty()) b.explained = -step_change(b.columns, b.r0, gauss_newton_step(b.columns, b.r0));
  return b;
}

double EffectFitter::screen(const ScreenBasis& basis, const EffectSet& base, const Effect& candidate,
                            const std::vector<double>& start) const {
  const EffectSet at = base.with(candidate, context_, start);
  std::vector<double> r_start;
  training_residuals(at, r_start);
  std::vector<std::vector<double>> columns = basis.columns;
  if (const int c = candidate.row->fitted_constant(); c >= 0 && !base.calibrated[static_cast<std::size_t>(c)]) {
    // The constant the candidate's law is referred to, or its curve multiplies, moves with it (unbounded,
    // like the basis).
    EffectSet moved = at;
    moved.calibration[static_cast<std::size_t>(c)] += kStep;
    columns.push_back(column(moved, r_start, kStep));
  }
  const std::size_t first = columns.size();
  const int p = candidate.row->parameters;
  for (int i = 0; i < p; ++i) {
    // Step into the allowed side of a bound (a delay or a conductance may start on its lower one).
    const double value = at.parameters.back()[static_cast<std::size_t>(i)];
    const double h = parameter_bounds(candidate, context_, i).second >= value + kStep ? kStep : -kStep;
    EffectSet moved = at;
    moved.parameters.back()[static_cast<std::size_t>(i)] += h;
    columns.push_back(column(moved, r_start, h));
  }
  const Eigen::VectorXd delta = bounded_step(columns, r_start, first, [&](int i) {
    const auto [lo, hi] = parameter_bounds(candidate, context_, i);
    const double value = at.parameters.back()[static_cast<std::size_t>(i)];
    return std::pair{lo - value, hi - value};
  });
  const double after = dot(r_start, r_start) + step_change(columns, r_start, delta);
  const double baseline_after = dot(basis.r0, basis.r0) - basis.explained;
  return std::max(0.0, baseline_after - after);
}

std::pair<std::vector<double>, double> EffectFitter::best_start(const ScreenBasis& basis, const EffectSet& base,
                                                                const Effect& candidate) const {
  const std::vector<std::vector<double>> starts =
      candidate.row->starts.empty() ? std::vector<std::vector<double>>{std::vector<double>(static_cast<std::size_t>(candidate.row->parameters), 0.0)}
                                    : candidate.row->starts;
  // The starts are a grid over a residual that is not convex in the candidate's parameters: each is judged
  // by the training sum of squares at that point, with the calibrated constants and the effects already
  // found moved to their best (the basis' linear step) — not by the candidate's own first step, which
  // from a point far from the answer extrapolates (a delay's step from 0 runs to its bound).
  std::vector<double> best;
  double best_ssr = std::numeric_limits<double>::infinity();
  std::vector<double> r;
  for (std::vector<double> s : starts) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      const auto [lo, hi] = parameter_bounds(candidate, context_, static_cast<int>(i));
      s[i] = std::clamp(s[i], lo, hi);
    }
    double ssr = 0.0;
    if (starts.size() > 1) {
      training_residuals(base.with(candidate, context_, s), r);
      ssr = dot(r, r);
      if (!basis.columns.empty()) ssr += step_change(basis.columns, r, gauss_newton_step(basis.columns, r));
    }
    if (ssr < best_ssr) {
      best_ssr = ssr;
      best = s;
    }
  }
  return {best, screen(basis, base, candidate, best)};
}

EffectSet EffectFitter::fit(const EffectSet& start, double* training_ssr) const {
  EffectSet set = start;
  Layout layout;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (set.calibrated[i]) layout.free.push_back(i);
  }
  std::vector<double> calibration(layout.free.size());
  for (std::size_t j = 0; j < layout.free.size(); ++j) calibration[j] = set.calibration[layout.free[j]];

  ceres::NumericDiffOptions diff;
  diff.relative_step_size = kStep;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<ReplayCost, ceres::FORWARD>(new ReplayCost(*this, set, layout),
                                                                                     ceres::TAKE_OWNERSHIP, diff);
  std::vector<double*> blocks;
  if (!calibration.empty()) {
    cost->AddParameterBlock(static_cast<int>(calibration.size()));
    blocks.push_back(calibration.data());
  }
  for (auto& p : set.parameters) {
    cost->AddParameterBlock(static_cast<int>(p.size()));
    blocks.push_back(p.data());
  }
  if (blocks.empty()) {
    if (training_ssr) *training_ssr = this->training_ssr(set);
    return set;
  }
  cost->SetNumResiduals(static_cast<int>(2 * training_.size()));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, blocks);
  bound_parameters(problem, blocks, calibration.size(), set, context_);
  ceres::Solver::Summary summary;
  ceres::Solve(fit_options(), &problem, &summary);
  if (training_ssr) *training_ssr = 2.0 * summary.final_cost;  // Ceres' cost is half the sum of squares
  for (std::size_t j = 0; j < layout.free.size(); ++j) set.calibration[layout.free[j]] = calibration[j];
  return set;
}

CalibrationIntervals EffectFitter::intervals(const EffectSet& set, double noise_floor_A) const {
  // Columns: every calibrated constant (free or not: the excitation is judged for all), then the effects'.
  std::vector<double> r0;
  training_residuals(set, r0);
  std::vector<std::vector<double>> columns;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    EffectSet moved = set;
    moved.calibration[i] += kStep;
    columns.push_back(column(moved, r0, kStep));
  }
  for (std::size_t j = 0; j < set.effects.size(); ++j) {
    for (std::size_t i = 0; i < set.parameters[j].size(); ++i) {
      EffectSet moved = set;
      const double h = parameter_bounds(set.effects[j], context_, static_cast<int>(i)).second >= set.parameters[j][i] + kStep ? kStep : -kStep;
      moved.parameters[j][i] += h;
      columns.push_back(column(moved, r0, h));
    }
  }
  const auto n = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd h(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j <= i; ++j) h(i, j) = h(j, i) = dot(columns[static_cast<std::size_t>(i)], columns[static_cast<std::size_t>(j)]);
  }
  // Cluster-robust "meat": the training blocks' score vectors g_b = J_bᵀ·r_b.
  const LogData& log = replay_.log();
  const std::size_t clusters = static_cast<std::size_t>(log.blocks) / 2 + 1;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(clusters));
  for (std::size_t j = 0; j < training_.size(); ++j) {
    const auto b = static_cast<Eigen::Index>(log.block[training_[j]] / 2);
    for (Eigen::Index c = 0; c < n; ++c) {
      const auto& col = columns[static_cast<std::size_t>(c)];
      g(c, b) += col[2 * j] * r0[2 * j] + col[2 * j + 1] * r0[2 * j + 1];
    }
  }
  // A constant the log does not excite has a vanishing column: the pseudo-inverse leaves it infinitely uncertain.
  const ClusterRobustCovariance cov = cluster_robust_covariance(h, g);
  const Eigen::MatrixXd& h_inv = cov.excitation;
  const Eigen::MatrixXd& robust = cov.robust;
  const Eigen::VectorXd& unexcited = cov.unexcited;
  const double sigma2 = 0.5 * noise_floor_A * noise_floor_A;  // per residual component
  CalibrationIntervals out;
  constexpr double kZ = 1.959964;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const double factor = 1.0 + kCalibrationScale * set.calibration[i];
    const bool excited = unexcited[k] < 0.5;
    out.half_width[i] = excited ? kZ * kCalibrationScale * std::sqrt(std::max(robust(k, k), 0.0)) / factor : kInf;
    out.change_per_A[i] = excited ? kCalibrationScale * std::sqrt(std::max(h_inv(k, k), 0.0)) / factor : kInf;
    out.excitation_half_width[i] = excited ? kZ * kCalibrationScale * std::sqrt(sigma2 * h_inv(k, k)) / factor : kInf;
  }
  auto k = static_cast<Eigen::Index>(kCalibrated.size());
  for (const auto& p : set.parameters) {
    std::vector<double> hw;
    for (std::size_t i = 0; i < p.size(); ++i, ++k) {
      hw.push_back(unexcited[k] < 0.5 ? kZ * std::sqrt(std::max(robust(k, k), 0.0)) : kInf);
    }
    out.effect_half_width.push_back(hw);
  }
  return out;
}

}  // namespace rpem::analysis
