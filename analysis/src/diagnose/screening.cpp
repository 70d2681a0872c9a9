// EffectFitter::screen (effect_fit.hpp): a round's candidates ranked by the first Gauss–Newton step, from two
// passes over the training blocks in which every model of the round streams together. The basis — the
// round's model and its columns (the free calibrated constants, the parameters of the effects in it) — is
// replayed in both, so that no column is stored: the first pass judges the candidates' starts, the second
// takes the chosen starts' columns together with the basis'.
#include <cassert>
#include <limits>

#include "least_squares.hpp"
#include "over_training.hpp"

namespace rpem::analysis {
namespace {

/// A column of the Jacobian: the model moved by h along one parameter.
struct Column {
  ExtendedModel moved;
  double h = kDifferenceStep;
};

/// The columns of the basis: the free calibrated constants, then the parameters of the effects in the
/// model (the effects already in the model move with the candidate too: an effect fitted without the one
/// still missing has taken part of its residual — a dead time fitted without the command delay — and a
/// screening that held it fixed would credit the missing effect with only what is left; a parameter its
/// bounds pin, width below kDifferenceStep, stays where it is).
std::vector<Column> basis_columns(const EffectSet& base, const EffectContext& context) {
  std::vector<Column> out;
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (!base.calibrated[i]) continue;
    EffectSet moved = base;
    moved.calibration[i] += kDifferenceStep;
    out.push_back({moved.model(context), kDifferenceStep});
  }
  for (std::size_t j = 0; j < base.effects.size(); ++j) {
    for (std::size_t i = 0; i < base.parameters[j].size(); ++i) {
      const auto [lo, hi] = parameter_bounds(base.effects[j], context, static_cast<int>(i));
      if (hi - lo < kDifferenceStep) continue;
      EffectSet moved = base;
      const double h = hi >= base.parameters[j][i] + kDifferenceStep ? kDifferenceStep : -kDifferenceStep;
      moved.parameters[j][i] += h;
      out.push_back({moved.model(context), h});
    }
  }
  return out;
}

/// The starts a candidate's row offers (zero if none), clamped to its bounds.
std::vector<std::vector<double>> starts_of(const Effect& candidate, const EffectContext& context) {
  std::vector<std::vector<double>> starts =
      candidate.row->starts.empty()
          ? std::vector<std::vector<double>>{std::vector<double>(static_cast<std::size_t>(candidate.row->parameters), 0.0)}
          : candidate.row->starts;
  for (std::vector<double>& s : starts) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      const auto [lo, hi] = parameter_bounds(candidate, context, static_cast<int>(i));
      s[i] = std::clamp(s[i], lo, hi);
    }
  }
  return starts;
}

/// Columns a screening's sums take at most (the basis' and a candidate's).
constexpr Eigen::Index kMaxScreeningColumns = 64;

/// The models of a pass: the basis (the round's model, then its columns) and after it whatever the pass
/// adds; each sample's basis columns are computed once for all. After the first pass: the basis' sums.
struct Pass {
  std::vector<ExtendedModel> models;
  std::vector<double> basis_steps;
  double baseline_after = 0.0;  ///< training sum of squares once the basis' columns moved to their best [A²]
  [[nodiscard]] std::size_t basis_end() const noexcept { return 1 + basis_steps.size(); }
  [[nodiscard]] Eigen::Index basis_size() const noexcept { return static_cast<Eigen::Index>(basis_steps.size()); }
  /// The basis columns at one sample, axis by axis.
  void basis_columns(std::span<const core::Vec2> r, int axis, double* c) const {
    assert(basis_steps.size() <= static_cast<std::size_t>(kMaxScreeningColumns));
    for (std::size_t i = 0; i < basis_steps.size(); ++i) c[i] = (r[i + 1][axis] - r[0][axis]) / basis_steps[i];
  }
};

/// The screening's first pass: the round's model's sums and each candidate's best start (out.ssr, out.starts).
template <class OverTraining>
void judge_starts(const OverTraining& over_training, const EffectContext& context, Pass& pass, const EffectSet& base,
                  const std::vector<Effect>& candidates, Screening& out) {
  const Eigen::Index nb = pass.basis_size();
  // Pass 1: the basis' own sums, and at each start of a candidate with several its sum of squares and its
  // residual's products with the basis' columns. The starts are a grid over a residual that is not convex in
  // the candidate's parameters: each is judged by the training sum of squares at that point, with the
  // calibrated constants and the effects already found moved to their best (the basis' linear step) — not
  // by the candidate's own first step, which from a point far from the answer extrapolates (a delay's step
  // from 0 runs to its bound).
  std::vector<std::vector<std::vector<double>>> starts(candidates.size());
  std::vector<std::size_t> first_start(candidates.size(), 0);  // index of the candidate's first start model
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    starts[c] = starts_of(candidates[c], context);
    first_start[c] = pass.models.size();
    if (starts[c].size() < 2) continue;
    for (const std::vector<double>& s : starts[c])
      pass.models.push_back(base.with(candidates[c], context, s).model(context));
  }
  struct First {
    least_squares::Gram basis;
    std::vector<double> ss;           ///< per start model: rᵀr
    std::vector<Eigen::VectorXd> br;  ///< per start model: basis columnsᵀ·r
  };
  const std::size_t start_models = pass.models.size() - pass.basis_end();
  const First init{least_squares::Gram(nb), std::vector<double>(start_models, 0.0),
                   std::vector<Eigen::VectorXd>(start_models, Eigen::VectorXd::Zero(nb))};
  const std::vector<First> first = over_training(pass.models, init, [&](First& f, std::span<const core::Vec2> r) {
    for (int axis = 0; axis < 2; ++axis) {
      double c[kMaxScreeningColumns];
      pass.basis_columns(r, axis, c);
      f.basis.add(c, r[0][axis]);
      for (std::size_t s = 0; s < start_models; ++s) {
        const double rs = r[pass.basis_end() + s][axis];
        f.ss[s] += rs * rs;
        for (Eigen::Index i = 0; i < nb; ++i) f.br[s][i] += c[i] * rs;
      }
    }
  });
  First sum = init;
  for (const First& f : first) {
    sum.basis.add(f.basis);
    for (std::size_t s = 0; s < start_models; ++s) {
      sum.ss[s] += f.ss[s];
      sum.br[s] += f.br[s];
    }
  }
  const Eigen::MatrixXd basis_jj = sum.basis.symmetric();
  const double explained =
      nb > 0 ? -least_squares::step_change(basis_jj, sum.basis.jr, least_squares::gauss_newton_step(basis_jj, sum.basis.jr))
             : 0.0;
  pass.baseline_after = sum.basis.rr - explained;
  out.ssr = sum.basis.rr;
  out.starts.resize(candidates.size());
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (starts[c].size() < 2) {
      out.starts[c] = starts[c].front();
      continue;
    }
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < starts[c].size(); ++s) {
      const std::size_t m = first_start[c] - pass.basis_end() + s;
      double ssr = sum.ss[m];
      if (nb > 0)
        ssr += least_squares::step_change(basis_jj, sum.br[m], least_squares::gauss_newton_step(basis_jj, sum.br[m]));
      if (ssr < best) {
        best = ssr;
        out.starts[c] = starts[c][s];
      }
    }
  }
}

/// The second: each candidate's credited gain from its start (out.gain).
template <class OverTraining>
void credit_gains(const OverTraining& over_training, const EffectContext& context, Pass& pass, const EffectSet& base,
                  const std::vector<Effect>& candidates, Screening& out) {
  const Eigen::Index nb = pass.basis_size();
  // Pass 2: each candidate at its start, its columns — the constant its law is referred to, or its curve
  // multiplies, where the base does not calibrate it (unbounded, like the basis), then its parameters,
  // stepped into the allowed side of a bound (a delay or a conductance may start on its lower one) — with
  // the basis' columns.
  pass.models.resize(pass.basis_end());
  struct Candidate {
    std::size_t model = 0;      ///< its model at the start; its columns' models follow
    std::vector<double> steps;  ///< its columns' steps
    Eigen::Index constant = 0;  ///< 1 if its first column is a constant's
  };
  std::vector<Candidate> layout(candidates.size());
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const Effect& e = candidates[c];
    const EffectSet at = base.with(e, context, out.starts[c]);
    Candidate& l = layout[c];
    l.model = pass.models.size();
    pass.models.push_back(at.model(context));
    if (const int k = e.row->fitted_constant(); k >= 0 && !base.calibrated[static_cast<std::size_t>(k)]) {
      EffectSet moved = at;
      moved.calibration[static_cast<std::size_t>(k)] += kDifferenceStep;
      pass.models.push_back(moved.model(context));
      l.steps.push_back(kDifferenceStep);
      l.constant = 1;
    }
    for (int i = 0; i < e.row->parameters; ++i) {
      const double value = at.parameters.back()[static_cast<std::size_t>(i)];
      const double h =
          parameter_bounds(e, context, i).second >= value + kDifferenceStep ? kDifferenceStep : -kDifferenceStep;
      EffectSet moved = at;
      moved.parameters.back()[static_cast<std::size_t>(i)] += h;
      pass.models.push_back(moved.model(context));
      l.steps.push_back(h);
    }
  }
  // Per candidate, the Gram of [basis columns, its columns] against its residual at the start.
  std::vector<least_squares::Gram> init2;
  init2.reserve(layout.size());
  for (const Candidate& l : layout) init2.emplace_back(nb + static_cast<Eigen::Index>(l.steps.size()));
  const std::vector<std::vector<least_squares::Gram>> second =
      over_training(pass.models, init2, [&](std::vector<least_squares::Gram>& g, std::span<const core::Vec2> r) {
        for (int axis = 0; axis < 2; ++axis) {
          double c[kMaxScreeningColumns];
          pass.basis_columns(r, axis, c);
          for (std::size_t j = 0; j < layout.size(); ++j) {
            const Candidate& l = layout[j];
            const double rs = r[l.model][axis];
            for (std::size_t i = 0; i < l.steps.size(); ++i) {
              c[static_cast<std::size_t>(nb) + i] = (r[l.model + 1 + i][axis] - rs) / l.steps[i];
            }
            g[j].add(c, rs);
          }
        }
      });
  out.gain.resize(candidates.size());
  const double baseline_after = pass.baseline_after;
  for (std::size_t j = 0; j < candidates.size(); ++j) {
    least_squares::Gram g = init2[j];
    for (const auto& block : second) g.add(block[j]);
    const Eigen::MatrixXd jj = g.symmetric();
    const Effect& e = candidates[j];
    const Eigen::Index first_parameter = nb + layout[j].constant;
    const Eigen::VectorXd delta = least_squares::bounded_step(jj, g.jr, first_parameter, [&](int i) {
      const auto [lo, hi] = parameter_bounds(e, context, i);
      const double value = out.starts[j][static_cast<std::size_t>(i)];
      return std::pair{lo - value, hi - value};
    });
    const double after = g.rr + least_squares::step_change(jj, g.jr, delta);
    out.gain[j] = std::max(0.0, baseline_after - after);
  }
}

}  // namespace

Screening EffectFitter::screen(const EffectSet& base, const std::vector<Effect>& candidates) const {
  Pass pass;
  pass.models.push_back(base.model(context_));
  for (Column& c : basis_columns(base, context_)) {
    pass.models.push_back(std::move(c.moved));
    pass.basis_steps.push_back(c.h);
  }
  if (Monitor* monitor = replay_.monitor()) {
    // Both passes' models: the basis twice, the starts of candidates with several, each candidate at its
    // start with its columns.
    std::uint64_t models = 2 * (1 + static_cast<std::uint64_t>(pass.basis_size()));
    for (const Effect& e : candidates) {
      const std::size_t starts = e.row->starts.size();
      models +=
          (starts > 1 ? starts : 0) + 1 + static_cast<std::uint64_t>(e.row->parameters) +
          (e.row->fitted_constant() >= 0 && !base.calibrated[static_cast<std::size_t>(e.row->fitted_constant())] ? 1 : 0);
    }
    monitor->add_work(models * training_block_samples_);
  }
  const auto over = [this](const std::vector<ExtendedModel>& models, const auto& init, const auto& add) {
    return over_training(models, init, add);
  };
  Screening out;
  judge_starts(over, context_, pass, base, candidates, out);
  credit_gains(over, context_, pass, base, candidates, out);
  return out;
}

}  // namespace rpem::analysis
