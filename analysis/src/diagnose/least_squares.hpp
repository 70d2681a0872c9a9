#pragma once
// The linear least squares of the fits and the screening, from sums over the samples rather than from the
// per-sample columns (effect_fit.hpp): Gram (JᵀJ, Jᵀr, rᵀr), the triangular factor of [J r]'s QR
// decomposition, and the Gauss–Newton steps that the screening takes from them.

#include <Eigen/Dense>
#include <algorithm>
#include <utility>
#include <vector>

namespace rpem::analysis::least_squares {

/// JᵀJ, Jᵀr and rᵀr over rows given one at a time (a residual component and its columns' values).
struct Gram {
  Eigen::MatrixXd jj;  ///< lower triangle until symmetric() is called
  Eigen::VectorXd jr;
  double rr = 0.0;

  explicit Gram(Eigen::Index columns = 0)
      : jj(Eigen::MatrixXd::Zero(columns, columns)), jr(Eigen::VectorXd::Zero(columns)) {}
  /// One row: the columns' values c and the residual r.
  void add(const double* c, double r) noexcept {
    for (Eigen::Index i = 0; i < jr.size(); ++i) {
      jr[i] += c[i] * r;
      for (Eigen::Index j = 0; j <= i; ++j) jj(i, j) += c[i] * c[j];
    }
    rr += r * r;
  }
  void add(const Gram& other) {
    jj += other.jj;
    jr += other.jr;
    rr += other.rr;
  }
  /// JᵀJ with its upper triangle filled.
  [[nodiscard]] Eigen::MatrixXd symmetric() const { return jj.selfadjointView<Eigen::Lower>(); }
};

/// The upper-triangular factor R of the QR decomposition of a tall matrix whose rows come a few at a time
/// (Householder reflections on [R; new rows]): RᵀR = AᵀA and, for the matrix [J r], ‖J·δ + r‖ = ‖R_J·δ + R_r‖
/// for every δ. Rows are folded in the order given, so the factor is the same whoever gives them.
class TriangularFactor {
 public:
  explicit TriangularFactor(Eigen::Index columns = 0);
  void add_row(const double* row);
  /// Adds the rows of another factor (the rows that factor was built from, as far as R is concerned).
  void add(TriangularFactor other);
  /// R, columns × columns (zero rows where fewer rows than columns were given).
  [[nodiscard]] Eigen::MatrixXd r();

 private:
  static constexpr Eigen::Index kBatch = 256;
  void fold();
  Eigen::MatrixXd r_;      ///< up to columns rows
  Eigen::MatrixXd batch_;  ///< rows not yet folded
  Eigen::Index filled_ = 0;
};

/// The Gauss–Newton parameter change δ = −(JᵀJ)⁻¹·Jᵀr that minimises |r + J·δ|² (a tiny ridge keeps
/// columns that vanish at the start harmless).
[[nodiscard]] Eigen::VectorXd gauss_newton_step(const Eigen::MatrixXd& jj, const Eigen::VectorXd& jr);

/// SSR(r + J·δ) − SSR(r), the change a parameter change δ makes in the linearisation: 2δᵀJᵀr + δᵀJᵀJδ.
[[nodiscard]] double step_change(const Eigen::MatrixXd& jj, const Eigen::VectorXd& jr, const Eigen::VectorXd& delta);

/// The Gauss–Newton step with the parameters from column `first` on kept within their bounds on the change
/// (bounds(i) for the i-th of them, i = 0 …): a parameter whose step would leave them is held at the bound
/// and the rest re-solved (an active set; a candidate has at most a few parameters).
template <class Bounds>
Eigen::VectorXd bounded_step(const Eigen::MatrixXd& jj, const Eigen::VectorXd& jr, Eigen::Index first,
                             const Bounds& bounds) {
  const Eigen::Index n = jr.size();
  std::vector<bool> held(static_cast<std::size_t>(n), false);
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(n);
  for (Eigen::Index pass = 0; pass <= n - first; ++pass) {
    // Jᵀ of the residual after the held changes, for the free columns; solve for those.
    std::vector<Eigen::Index> free;
    for (Eigen::Index c = 0; c < n; ++c) {
      if (!held[static_cast<std::size_t>(c)]) free.push_back(c);
    }
    Eigen::MatrixXd jj_free(static_cast<Eigen::Index>(free.size()), static_cast<Eigen::Index>(free.size()));
    Eigen::VectorXd jr_free(static_cast<Eigen::Index>(free.size()));
    for (std::size_t a = 0; a < free.size(); ++a) {
      double g = jr[free[a]];
      for (Eigen::Index c = 0; c < n; ++c) {
        if (held[static_cast<std::size_t>(c)]) g += jj(free[a], c) * delta[c];
      }
      jr_free[static_cast<Eigen::Index>(a)] = g;
      for (std::size_t b = 0; b < free.size(); ++b)
        jj_free(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = jj(free[a], free[b]);
    }
    const Eigen::VectorXd step = free.empty() ? Eigen::VectorXd() : gauss_newton_step(jj_free, jr_free);
    bool violated = false;
    for (std::size_t a = 0; a < free.size(); ++a) {
      const Eigen::Index c = free[a];
      delta[c] = step[static_cast<Eigen::Index>(a)];
      if (c < first) continue;
      const auto [lo, hi] = bounds(static_cast<int>(c - first));
      if (delta[c] < lo || delta[c] > hi) {
        delta[c] = std::clamp(delta[c], lo, hi);
        held[static_cast<std::size_t>(c)] = true;
        violated = true;
      }
    }
    if (!violated) break;
  }
  return delta;
}

}  // namespace rpem::analysis::least_squares
