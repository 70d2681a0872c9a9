#include "rpem/analysis/diagnose/effect_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

#include "least_squares.hpp"
#include "over_training.hpp"
#include "rpem/analysis/cluster_robust.hpp"

namespace rpem::analysis {
namespace {

/// Columns a fit's or the intervals' per-sample rows hold at most (the calibrated constants and every
/// effect's parameters; four effects of at most a few parameters use a fraction of it).
constexpr int kMaxFitColumns = 64;

/// A training block's residuals (scaled by the loss, as over_training gives them) and their sum of squares.
struct TrainingResiduals {
  double ssr = 0.0;
  std::vector<core::Vec2> r;
};

void add_training_residual(TrainingResiduals& b, std::span<const core::Vec2> r) {
  b.ssr += r[0][0] * r[0][0];
  b.ssr += r[0][1] * r[0][1];
  b.r.push_back(r[0]);
}

/// The training sum of squares from the blocks' sums, added in block order (as EffectFitter::training_ssr).
double training_ssr_of(const std::vector<TrainingResiduals>& blocks) {
  double s = 0.0;
  for (const TrainingResiduals& b : blocks) s += b.ssr;
  return s;
}

}  // namespace

/// The fit as a Ceres cost: the free calibrated constants (one block, if any) and one block per effect;
/// as residuals the triangular factor of the training blocks' [J r] (effect_fit.hpp), P + 1 of them, and
/// where Ceres asks for the cost alone, P zeros and the root of the sum of squares. After an accepted step
/// Ceres asks for the cost at the new point and then for the Jacobian there: the cost's replay keeps the
/// training residuals, and the Jacobian's replays only the steps.
class EffectFitter::FitCost final : public ceres::CostFunction {
 public:
  FitCost(const EffectFitter& fitter, const EffectSet& start, std::vector<std::size_t> free)
      : fitter_(fitter), start_(start), free_(std::move(free)) {
    if (!free_.empty()) mutable_parameter_block_sizes()->push_back(static_cast<std::int32_t>(free_.size()));
    for (const Effect& e : start_.effects) mutable_parameter_block_sizes()->push_back(e.row->parameters);
    for (std::int32_t size : parameter_block_sizes()) parameters_ += size;
    set_num_residuals(parameters_ + 1);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const EffectSet set = at(parameters);
    const int p = parameters_;
    assert(p < kMaxFitColumns);  // the row below holds the P columns and the residual
    if (jacobians == nullptr) {
      cost_only(set, parameters, residuals);
      return true;
    }
    // The base point's residuals: those of the cost-only evaluation just before if it was at these parameters
    // bit for bit (the replay is deterministic: the same rows), else model 0 of this replay.
    const bool known = !last_residuals_.empty() && last_point_ == point(parameters);
    std::vector<TrainingResiduals> base = std::move(last_residuals_);
    last_residuals_.clear();
    if (!known) base.assign(fitter_.training_blocks_.size(), TrainingResiduals{});
    // The point (unless known) and each parameter stepped forward as Ceres' numeric differentiation steps it.
    std::vector<ExtendedModel> models;
    if (!known) models.push_back(set.model(fitter_.context_));
    const std::size_t stepped = known ? 0 : 1;  // index of the first stepped model
    std::vector<double> inverse_step;
    add_stepped_models(parameters, models, inverse_step);
    const std::vector<std::int32_t>& sizes = parameter_block_sizes();
    struct Block {
      least_squares::TriangularFactor factor;
      const std::vector<core::Vec2>* base = nullptr;  ///< the known residuals, if known
      std::size_t next = 0;
    };
    std::vector<Block> inits;
    inits.reserve(base.size());
    for (const TrainingResiduals& b : base)
      inits.push_back(Block{least_squares::TriangularFactor(p + 1), known ? &b.r : nullptr, 0});
    std::vector<Block> factors =
        fitter_.over_training_from(models, std::move(inits), [&](Block& f, std::span<const core::Vec2> r) {
          const core::Vec2 r0 = f.base ? (*f.base)[f.next++] : r[0];
          double row[kMaxFitColumns];
          for (int axis = 0; axis < 2; ++axis) {
            for (int j = 0; j < p; ++j)
              row[j] =
                  (r[static_cast<std::size_t>(j) + stepped][axis] - r0[axis]) * inverse_step[static_cast<std::size_t>(j)];
            row[p] = r0[axis];
            f.factor.add_row(row);
          }
        });
    least_squares::TriangularFactor all(p + 1);
    for (Block& f : factors) {
      assert(!f.base || f.next == f.base->size());  // the same samples as the cost-only evaluation's
      all.add(std::move(f.factor));
    }
    const Eigen::MatrixXd r = all.r();
    for (int i = 0; i <= p; ++i) residuals[i] = r(i, p);
    int column = 0;
    for (std::size_t b = 0; b < sizes.size(); ++b) {
      for (std::int32_t i = 0; i < sizes[b]; ++i, ++column) {
        if (jacobians[b] == nullptr) continue;
        for (int row = 0; row <= p; ++row) jacobians[b][row * sizes[b] + i] = r(row, column);
      }
    }
    return true;
  }

 private:
  /// The cost alone at `set` (Ceres' `parameters`): P zeros and the root of the training sum of squares. The
  /// training residuals are kept with their point: at an accepted step Ceres asks for the Jacobian there next.
  /// (The last point's are released first: one set per fit at any time.)
  void cost_only(const EffectSet& set, double const* const* parameters, double* residuals) const {
    const int p = parameters_;
    last_residuals_.clear();
    std::vector<TrainingResiduals> blocks(fitter_.training_blocks_.size());
    const std::vector<std::size_t>& first = fitter_.replay_.log().block_first;
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      const auto b = static_cast<std::size_t>(fitter_.training_blocks_[i]);
      blocks[i].r.reserve(first[b + 1] - first[b]);
    }
    blocks = fitter_.over_training_from({set.model(fitter_.context_)}, std::move(blocks), add_training_residual);
    std::fill(residuals, residuals + p, 0.0);
    residuals[p] = std::sqrt(training_ssr_of(blocks));
    last_point_ = point(parameters);
    last_residuals_ = std::move(blocks);
  }

  /// Each parameter stepped forward as Ceres' numeric differentiation steps it: its model appended to
  /// `models`, the step's inverse to `inverse_step`.
  void add_stepped_models(double const* const* parameters, std::vector<ExtendedModel>& models,
                          std::vector<double>& inverse_step) const {
    const std::vector<std::int32_t>& sizes = parameter_block_sizes();
    for (std::size_t b = 0; b < sizes.size(); ++b) {
      for (std::int32_t i = 0; i < sizes[b]; ++i) {
        std::vector<double> block(parameters[b], parameters[b] + sizes[b]);
        const double delta = std::max(std::sqrt(std::numeric_limits<double>::epsilon()),
                                      std::abs(block[static_cast<std::size_t>(i)]) * kDifferenceStep);
        block[static_cast<std::size_t>(i)] += delta;
        std::vector<const double*> moved(parameters, parameters + sizes.size());
        moved[b] = block.data();
        models.push_back(at(moved.data()).model(fitter_.context_));
        inverse_step.push_back(1.0 / delta);
      }
    }
  }

  /// The set at Ceres' parameters.
  EffectSet at(double const* const* parameters) const {
    EffectSet set = start_;
    std::size_t block = 0;
    if (!free_.empty()) {
      for (std::size_t j = 0; j < free_.size(); ++j) set.calibration[free_[j]] = parameters[0][j];
      block = 1;
    }
    for (std::size_t j = 0; j < set.effects.size(); ++j, ++block) {
      const int n = set.effects[j].row->parameters;
      set.parameters[j].assign(parameters[block], parameters[block] + n);
    }
    return set;
  }

  /// Ceres' parameters, every block's in order (compared bit for bit: the replay at equal bits is the same).
  std::vector<std::uint64_t> point(double const* const* parameters) const {
    std::vector<std::uint64_t> out;
    const std::vector<std::int32_t>& sizes = parameter_block_sizes();
    for (std::size_t b = 0; b < sizes.size(); ++b) {
      for (std::int32_t i = 0; i < sizes[b]; ++i) out.push_back(std::bit_cast<std::uint64_t>(parameters[b][i]));
    }
    return out;
  }

  const EffectFitter& fitter_;
  EffectSet start_;
  std::vector<std::size_t> free_;
  int parameters_ = 0;
  // The last cost-only evaluation's point and training residuals (Ceres evaluates one problem's cost from one
  // thread at a time: num_threads 1). Released by the Jacobian evaluation that follows.
  mutable std::vector<std::uint64_t> last_point_;
  mutable std::vector<TrainingResiduals> last_residuals_;
};

EffectFitter::EffectFitter(const ModelReplay& replay, const EffectContext& context)
    : replay_(replay),
      context_(context),
      training_blocks_(replay.blocks(Blocks::kTraining)),
      heldout_blocks_(replay.blocks(Blocks::kHeldout)),
      fitted_(replay.log().size(), false) {
  for (int b : training_blocks_) {
    training_block_samples_ +=
        replay.log().block_first[static_cast<std::size_t>(b) + 1] - replay.log().block_first[static_cast<std::size_t>(b)];
  }
  // The samples the baseline predicts: every fit is judged on the same ones.
  const std::vector<ExtendedModel> base = {context_.base};
  std::vector<std::vector<std::size_t>> per_block(training_blocks_.size());
  replay_.for_blocks(training_blocks_, [&](std::size_t i, int b) {
    replay_.replay_block(b, base, [&](std::size_t k, std::span<const ModelSample> m) {
      if (m[0].valid) per_block[i].push_back(k);
    });
  });
  for (const auto& ks : per_block) {
    for (std::size_t k : ks) fitted_[k] = true;
    training_samples_ += ks.size();
  }
}

EffectFitter EffectFitter::with_loss(const RobustLoss& loss) const {
  EffectFitter f = *this;
  f.loss_ = loss;
  return f;
}

void EffectFitter::training_residuals(const EffectSet& set, std::vector<double>& out) const {
  const std::vector<std::vector<double>> blocks =
      over_training({set.model(context_)}, std::vector<double>{}, [](std::vector<double>& v, std::span<const core::Vec2> r) {
        v.push_back(r[0][0]);
        v.push_back(r[0][1]);
      });
  out.clear();
  for (const auto& b : blocks) out.insert(out.end(), b.begin(), b.end());
}

double EffectFitter::training_ssr(const EffectSet& set) const {
  const std::vector<double> blocks = over_training({set.model(context_)}, 0.0, [](double& s, std::span<const core::Vec2> r) {
    s += r[0][0] * r[0][0];
    s += r[0][1] * r[0][1];
  });
  double s = 0.0;
  for (double b : blocks) s += b;
  return s;
}

BlockScores EffectFitter::heldout(const EffectSet& set) const {
  const LogData& log = replay_.log();
  const std::vector<ExtendedModel> model = {set.model(context_)};
  std::vector<double> ssr(heldout_blocks_.size(), 0.0);
  std::vector<std::size_t> samples(heldout_blocks_.size(), 0);
  replay_.for_blocks(heldout_blocks_, [&](std::size_t i, int b) {
    replay_.replay_block(b, model, [&](std::size_t, std::span<const ModelSample> m) {
      if (!m[0].valid) return;
      ssr[i] += loss_.rho(m[0].residual_A.squaredNorm());
      ++samples[i];
    });
  });
  BlockScores out;
  out.ssr.assign(static_cast<std::size_t>(log.blocks / 2), 0.0);
  for (std::size_t i = 0; i < heldout_blocks_.size(); ++i) {
    out.ssr[static_cast<std::size_t>(heldout_blocks_[i] / 2)] = ssr[i];
    out.samples += samples[i];
  }
  return out;
}

double EffectFitter::change_correlation(const EffectSet& base, const EffectSet& a, const EffectSet& b) const {
  const std::vector<ExtendedModel> models = {base.model(context_), a.model(context_), b.model(context_)};
  std::vector<std::array<double, 3>> sums(heldout_blocks_.size(), {0.0, 0.0, 0.0});  // ab, aa, bb
  replay_.for_blocks(heldout_blocks_, [&](std::size_t i, int block) {
    replay_.replay_block(block, models, [&](std::size_t, std::span<const ModelSample> m) {
      if (!m[0].valid || !m[1].valid || !m[2].valid) return;
      const core::Vec2 da = m[1].model_A - m[0].model_A, db = m[2].model_A - m[0].model_A;
      sums[i][0] += da.dot(db);
      sums[i][1] += da.squaredNorm();
      sums[i][2] += db.squaredNorm();
    });
  });
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (const auto& s : sums) {
    ab += s[0];
    aa += s[1];
    bb += s[2];
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : 0.0;
}

EffectSet EffectFitter::fit(const EffectSet& start, double* training_ssr) const {
  EffectSet set = start;
  std::vector<std::size_t> free;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (set.calibrated[i]) free.push_back(i);
  }
  std::vector<double> calibration(free.size());
  for (std::size_t j = 0; j < free.size(); ++j) calibration[j] = set.calibration[free[j]];
  std::vector<double*> blocks;
  if (!calibration.empty()) blocks.push_back(calibration.data());
  for (auto& p : set.parameters) blocks.push_back(p.data());
  if (blocks.empty()) {
    if (training_ssr) *training_ssr = this->training_ssr(set);
    return set;
  }
  ceres::Problem problem;
  problem.AddResidualBlock(new FitCost(*this, set, free), nullptr, blocks);
  std::size_t block = 0;
  if (!calibration.empty()) {
    for (std::size_t j = 0; j < calibration.size(); ++j) {
      problem.SetParameterLowerBound(blocks[0], static_cast<int>(j), -kCalibrationBound);
      problem.SetParameterUpperBound(blocks[0], static_cast<int>(j), kCalibrationBound);
    }
    block = 1;
  }
  for (std::size_t j = 0; j < set.effects.size(); ++j, ++block) {
    for (int i = 0; i < set.effects[j].row->parameters; ++i) {
      const auto [lo, hi] = parameter_bounds(set.effects[j], context_, i);
      if (std::isfinite(lo)) problem.SetParameterLowerBound(blocks[block], i, lo);
      if (std::isfinite(hi)) problem.SetParameterUpperBound(blocks[block], i, hi);
    }
  }
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
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (training_ssr) *training_ssr = 2.0 * summary.final_cost;  // Ceres' cost is half the sum of squares
  for (std::size_t j = 0; j < free.size(); ++j) set.calibration[free[j]] = calibration[j];
  return set;
}

namespace {

/// The models of the intervals' Jacobian: `set` itself, then one per column, each with its step in `steps`.
/// Columns: every calibrated constant (free or not: the excitation is judged for all), then the effects'
/// parameters (stepped back where a step forward would pass the upper bound).
std::vector<ExtendedModel> stepped_models(const EffectSet& set, const EffectContext& context, std::vector<double>& steps) {
  std::vector<ExtendedModel> models = {set.model(context)};
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    EffectSet moved = set;
    moved.calibration[i] += kDifferenceStep;
    models.push_back(moved.model(context));
    steps.push_back(kDifferenceStep);
  }
  for (std::size_t j = 0; j < set.effects.size(); ++j) {
    for (std::size_t i = 0; i < set.parameters[j].size(); ++i) {
      EffectSet moved = set;
      const double h =
          parameter_bounds(set.effects[j], context, static_cast<int>(i)).second >= set.parameters[j][i] + kDifferenceStep
              ? kDifferenceStep
              : -kDifferenceStep;
      moved.parameters[j][i] += h;
      models.push_back(moved.model(context));
      steps.push_back(h);
    }
  }
  return models;
}

}  // namespace

CalibrationIntervals EffectFitter::intervals(const EffectSet& set, double noise_floor_A) const {
  std::vector<double> steps;
  const std::vector<ExtendedModel> models = stepped_models(set, context_, steps);
  const auto n = static_cast<Eigen::Index>(steps.size());
  assert(n <= kMaxFitColumns);
  // Per training block: JᵀJ, and the block's score vector g_b = J_bᵀ·r_b (the cluster-robust "meat").
  struct Block {
    least_squares::Gram gram;
    Eigen::VectorXd score;
  };
  const std::vector<Block> blocks = over_training(models, Block{least_squares::Gram(n), Eigen::VectorXd::Zero(n)},
                                                  [&](Block& b, std::span<const core::Vec2> r) {
                                                    double c[2][kMaxFitColumns];
                                                    for (Eigen::Index i = 0; i < n; ++i) {
                                                      const std::size_t m = static_cast<std::size_t>(i) + 1;
                                                      c[0][i] = (r[m][0] - r[0][0]) / steps[static_cast<std::size_t>(i)];
                                                      c[1][i] = (r[m][1] - r[0][1]) / steps[static_cast<std::size_t>(i)];
                                                      b.score[i] += c[0][i] * r[0][0] + c[1][i] * r[0][1];
                                                    }
                                                    b.gram.add(c[0], r[0][0]);
                                                    b.gram.add(c[1], r[0][1]);
                                                  });
  least_squares::Gram total(n);
  for (const Block& b : blocks) total.add(b.gram);
  const Eigen::MatrixXd h = total.symmetric();
  // Cluster-robust "meat": the training blocks' score vectors.
  const LogData& log = replay_.log();
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(log.blocks) / 2 + 1);
  for (std::size_t i = 0; i < training_blocks_.size(); ++i) g.col(training_blocks_[i] / 2) = blocks[i].score;
  // A constant the log does not excite has a vanishing column: the pseudo-inverse leaves it infinitely uncertain.
  const ClusterRobustCovariance cov = cluster_robust_covariance(h, g);
  const Eigen::MatrixXd& h_inv = cov.excitation;
  const Eigen::MatrixXd& robust = cov.robust;
  const double sigma2 = 0.5 * noise_floor_A * noise_floor_A;  // per residual component
  CalibrationIntervals out;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const double factor = 1.0 + kCalibrationScale * set.calibration[i];
    const bool excited = cov.excited(k);
    out.half_width[i] = excited ? kZ95 * kCalibrationScale * std::sqrt(std::max(robust(k, k), 0.0)) / factor : kInf;
    out.change_per_A[i] = excited ? kCalibrationScale * std::sqrt(std::max(h_inv(k, k), 0.0)) / factor : kInf;
    out.excitation_half_width[i] = excited ? kZ95 * kCalibrationScale * std::sqrt(sigma2 * h_inv(k, k)) / factor : kInf;
  }
  auto k = static_cast<Eigen::Index>(kCalibrated.size());
  for (const auto& p : set.parameters) {
    std::vector<double> hw;
    for (std::size_t i = 0; i < p.size(); ++i, ++k) {
      hw.push_back(cov.excited(k) ? kZ95 * std::sqrt(std::max(robust(k, k), 0.0)) : kInf);
    }
    out.effect_half_width.push_back(hw);
  }
  return out;
}

}  // namespace rpem::analysis
