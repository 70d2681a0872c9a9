#include "rpem/analysis/cluster_robust.hpp"

#include <algorithm>
#include <cassert>

namespace rpem::analysis {

ClusterRobustCovariance cluster_robust_covariance(const Eigen::MatrixXd& normal, const Eigen::MatrixXd& scores) {
  const Eigen::Index n = normal.cols();
  assert(normal.rows() == n && scores.rows() == n);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normal);
  const double floor = 1e-12 * std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  ClusterRobustCovariance c{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd(), Eigen::VectorXd::Zero(n)};
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::VectorXd v = eig.eigenvectors().col(k);
    if (eig.eigenvalues()[k] > floor) {
      c.excitation += v * v.transpose() / eig.eigenvalues()[k];
    } else {
      c.unexcited += v.cwiseAbs2();
    }
  }
  Eigen::Index used = 0;
  for (Eigen::Index b = 0; b < scores.cols(); ++b) used += scores.col(b).squaredNorm() > 0.0 ? 1 : 0;
  const double correction = used > 1 ? static_cast<double>(used) / static_cast<double>(used - 1) : 1.0;
  c.robust = correction * c.excitation * (scores * scores.transpose()) * c.excitation;
  return c;
}

}  // namespace rpem::analysis
