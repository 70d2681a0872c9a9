#include "rpem/analysis/rs_along_current.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace rpem::analysis {

std::optional<RsAlongCurrent> fit_rs_along_current(const std::vector<RsReading>& readings) {
  constexpr std::size_t kParameters = 3;
  const std::size_t n = readings.size();
  if (n < 2 * kParameters) return std::nullopt;
  double t_mean_s = 0.0;
  for (const RsReading& r : readings) t_mean_s += r.t_s / static_cast<double>(n);
  Eigen::MatrixX3d x(static_cast<Eigen::Index>(n), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  RsAlongCurrent out;
  out.readings = n;
  out.current_min_A = out.current_max_A = readings.front().current_A;
  for (std::size_t k = 0; k < n; ++k) {
    const RsReading& r = readings[k];
    const auto row = static_cast<Eigen::Index>(k);
    x.row(row) << r.current_A, 1.0, (r.t_s - t_mean_s) * r.current_A;
    y(row) = r.voltage_V;
    out.current_min_A = std::min(out.current_min_A, r.current_A);
    out.current_max_A = std::max(out.current_max_A, r.current_A);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixX3d> qr(x);
  if (qr.rank() < static_cast<Eigen::Index>(kParameters)) return std::nullopt;
  const Eigen::Vector3d b = qr.solve(y);
  const double residual_variance = (y - x * b).squaredNorm() / static_cast<double>(n - kParameters);
  const Eigen::Matrix3d covariance = residual_variance * (x.transpose() * x).inverse();
  const Eigen::Vector3d at_last(1.0, 0.0, readings.back().t_s - t_mean_s);
  out.r_at_last_Ohm = at_last.dot(b);
  out.r_at_last_se_Ohm = std::sqrt(at_last.dot(covariance * at_last));
  out.v_V = b(1);
  out.v_se_V = std::sqrt(covariance(1, 1));
  return out;
}

}  // namespace rpem::analysis
