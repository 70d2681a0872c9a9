#pragma once
// Parameter uncertainty of a least-squares fit, as `rpem diagnose` and `rpem thermal fit` report it: the
// Gauss-Newton normal matrix H = JᵀJ inverted on the directions the data excite (a pseudo-inverse: a
// direction with an eigenvalue below 10⁻¹² of the largest is unexcited and left infinitely uncertain), and
// the cluster-robust sandwich c·H⁺·(Σ_b g_b g_bᵀ)·H⁺ over the residuals' clusters (g_b = J_bᵀ·r_b, the
// cluster's score; c = B/(B − 1) for the B clusters that carry one), which holds when the residuals within a
// cluster are correlated (docs/diagnose.md, "Confidence intervals").

#include <Eigen/Dense>

namespace rpem::analysis {

/// The standard normal's two-sided 95 % quantile: a 95 % interval is ±kZ95·σ.
inline constexpr double kZ95 = 1.959964;

struct ClusterRobustCovariance {
  Eigen::MatrixXd excitation;  ///< H⁺: the covariance per unit residual variance (white residuals)
  Eigen::MatrixXd robust;      ///< c·H⁺·G·Gᵀ·H⁺
  Eigen::VectorXd unexcited;   ///< per parameter: its weight in the unexcited directions (0 … 1)
  /// A parameter mostly outside the unexcited directions.
  [[nodiscard]] bool excited(Eigen::Index k) const { return unexcited[k] < 0.5; }
};

/// `normal` = JᵀJ (n×n, symmetric); `scores` = one column g_b per cluster (n×B; a zero column is a cluster
/// without residuals and does not count in c).
[[nodiscard]] ClusterRobustCovariance cluster_robust_covariance(const Eigen::MatrixXd& normal,
                                                                const Eigen::MatrixXd& scores);

}  // namespace rpem::analysis
