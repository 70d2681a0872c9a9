#include "rpem/analysis/diagnose/effect_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace rpem::analysis {
namespace {

/// Forward-difference step on the scaled parameters (1 = a typical magnitude).
constexpr double kStep = 1e-3;

/// The replay as a Ceres cost: one parameter block per effect, the training residuals as residuals.
class ReplayCost {
 public:
  ReplayCost(const EffectFitter& fitter, const std::vector<Effect>& effects) : fitter_(fitter), effects_(effects) {}

  bool operator()(double const* const* parameters, double* residuals) const {
    EffectSet set;
    set.effects = effects_;
    for (std::size_t j = 0; j < effects_.size(); ++j) {
      const int n = parameter_count(effects_[j], fitter_.context());
      set.parameters.emplace_back(parameters[j], parameters[j] + n);
    }
    fitter_.training_residuals(set, buffer_);
    std::copy(buffer_.begin(), buffer_.end(), residuals);
    return true;
  }

 private:
  const EffectFitter& fitter_;
  std::vector<Effect> effects_;
  mutable std::vector<double> buffer_;
};

}  // namespace

ExtendedModel EffectSet::model(const EffectContext& c) const {
  ExtendedModel m;
  m.extensions = c.base_extensions;
  for (std::size_t j = 0; j < effects.size(); ++j) apply(effects[j], parameters[j].data(), c, m);
  return m;
}

EffectSet EffectSet::with(const Effect& e, const EffectContext& c) const {
  EffectSet s = *this;
  s.effects.push_back(e);
  s.parameters.emplace_back(static_cast<std::size_t>(parameter_count(e, c)), 0.0);
  return s;
}

bool EffectSet::contains(const Effect& e) const { return std::find(effects.begin(), effects.end(), e) != effects.end(); }

double BlockScores::total() const {
  double t = 0.0;
  for (double s : ssr) t += s;
  return t;
}

EffectFitter::EffectFitter(const ModelReplay& replay, const EffectContext& context)
    : replay_(replay), context_(context) {
  ReplayOutput nominal;
  replay_.run(EffectSet{}.model(context_), nominal);
  const LogData& log = replay_.log();
  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (log.training(k) && nominal.valid[k]) training_.push_back(k);
  }
}

void EffectFitter::training_residuals(const EffectSet& set, std::vector<double>& out) const {
  ReplayOutput r;
  replay_.run(set.model(context_), r);
  out.resize(2 * training_.size());
  for (std::size_t j = 0; j < training_.size(); ++j) {
    const std::size_t k = training_[j];
    // A sample that stops being valid (non-finite) counts as a large miss rather than vanishing.
    const core::Vec2 e = r.valid[k] ? r.residual_A[k] : core::Vec2::Constant(1e3);
    out[2 * j] = e[0];
    out[2 * j + 1] = e[1];
  }
}

double EffectFitter::training_ssr(const EffectSet& set) const {
  std::vector<double> r;
  training_residuals(set, r);
  double s = 0.0;
  for (double x : r) s += x * x;
  return s;
}

BlockScores EffectFitter::heldout(const EffectSet& set) const {
  ReplayOutput r;
  replay_.run(set.model(context_), r);
  const LogData& log = replay_.log();
  BlockScores b;
  b.ssr.assign(static_cast<std::size_t>(log.blocks / 2), 0.0);
  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (!log.heldout(k) || !r.valid[k]) continue;
    b.ssr[static_cast<std::size_t>(log.block[k] / 2)] += r.residual_A[k].squaredNorm();
    ++b.samples;
  }
  return b;
}

double EffectFitter::screen(const EffectSet& base, const Effect& candidate) const {
  const EffectSet start = base.with(candidate, context_);
  std::vector<double> r0;
  training_residuals(start, r0);
  const int p = parameter_count(candidate, context_);
  Eigen::MatrixXd jac(static_cast<Eigen::Index>(r0.size()), p);
  std::vector<double> r;
  for (int i = 0; i < p; ++i) {
    // Step into the allowed side of a bound (delay and iron loss start on their lower one).
    const double h = parameter_bounds(candidate, context_, i).second >= kStep ? kStep : -kStep;
    EffectSet moved = start;
    moved.parameters.back()[static_cast<std::size_t>(i)] = h;
    training_residuals(moved, r);
    for (std::size_t j = 0; j < r.size(); ++j) jac(static_cast<Eigen::Index>(j), i) = (r[j] - r0[j]) / h;
  }
  const Eigen::Map<const Eigen::VectorXd> res(r0.data(), static_cast<Eigen::Index>(r0.size()));
  const Eigen::VectorXd g = jac.transpose() * res;
  const Eigen::MatrixXd h = jac.transpose() * jac;
  const Eigen::VectorXd step = -h.ldlt().solve(g);
  // A step that leaves a one-sided bound (delay < 0, conductance < 0) predicts nothing.
  for (int i = 0; i < p; ++i) {
    const auto [lo, hi] = parameter_bounds(candidate, context_, i);
    if (step[i] < lo || step[i] > hi) return 0.0;
  }
  return std::max(0.0, -g.dot(step));
}

EffectSet EffectFitter::fit(const EffectSet& start) const {
  EffectSet set = start;
  ceres::NumericDiffOptions diff;
  diff.relative_step_size = kStep;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<ReplayCost, ceres::FORWARD>(
      new ReplayCost(*this, set.effects), ceres::TAKE_OWNERSHIP, diff);
  std::vector<double*> blocks;
  for (auto& p : set.parameters) {
    cost->AddParameterBlock(static_cast<int>(p.size()));
    blocks.push_back(p.data());
  }
  cost->SetNumResiduals(static_cast<int>(2 * training_.size()));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, blocks);
  for (std::size_t j = 0; j < set.effects.size(); ++j) {
    for (int i = 0; i < parameter_count(set.effects[j], context_); ++i) {
      const auto [lo, hi] = parameter_bounds(set.effects[j], context_, i);
      if (std::isfinite(lo)) problem.SetParameterLowerBound(blocks[j], i, lo);
      if (std::isfinite(hi)) problem.SetParameterUpperBound(blocks[j], i, hi);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 25;
  options.function_tolerance = 1e-7;
  options.parameter_tolerance = 1e-6;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return set;
}

}  // namespace rpem::analysis
