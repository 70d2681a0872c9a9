#include "rpem/sim/flux_map.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "rpem/io/csv_table.hpp"

namespace rpem::sim {

FluxMap::FluxMap(std::vector<double> i_d_A, std::vector<double> i_q_A, std::vector<double> psi_d_Wb,
                 std::vector<double> psi_q_Wb)
    : i_d_(std::move(i_d_A)), i_q_(std::move(i_q_A)), psi_d_(std::move(psi_d_Wb)), psi_q_(std::move(psi_q_Wb)) {
  if (i_d_.size() < 2 || i_q_.size() < 2 || psi_d_.size() != i_d_.size() * i_q_.size() || psi_q_.size() != psi_d_.size()) {
    throw std::invalid_argument("flux map: grid needs at least 2×2 points and one value per point");
  }
  if (!std::is_sorted(i_d_.begin(), i_d_.end()) || !std::is_sorted(i_q_.begin(), i_q_.end())) {
    throw std::invalid_argument("flux map: axes must increase");
  }
}

FluxMap FluxMap::load_csv(const std::string& path) {
  const io::CsvTable t = io::CsvTable::read(path);
  const auto& id = t.column("i_d_A");
  const auto& iq = t.column("i_q_A");
  const auto& pd = t.column("psi_d_Vs");
  const auto& pq = t.column("psi_q_Vs");
  std::vector<double> d_axis(id.begin(), id.end()), q_axis(iq.begin(), iq.end());
  std::sort(d_axis.begin(), d_axis.end());
  d_axis.erase(std::unique(d_axis.begin(), d_axis.end()), d_axis.end());
  std::sort(q_axis.begin(), q_axis.end());
  q_axis.erase(std::unique(q_axis.begin(), q_axis.end()), q_axis.end());
  const std::size_t n = d_axis.size() * q_axis.size();
  if (t.rows() != n) {
    throw io::DataError(
        path, 0, 0, "",
        "expected a full grid of " + std::to_string(n) + " points, found " + std::to_string(t.rows()) + " rows");
  }
  std::vector<double> psi_d(n, std::nan("")), psi_q(n, std::nan(""));
  for (std::size_t r = 0; r < t.rows(); ++r) {
    const auto kd = static_cast<std::size_t>(std::lower_bound(d_axis.begin(), d_axis.end(), id[r]) - d_axis.begin());
    const auto kq = static_cast<std::size_t>(std::lower_bound(q_axis.begin(), q_axis.end(), iq[r]) - q_axis.begin());
    psi_d[kq * d_axis.size() + kd] = pd[r];
    psi_q[kq * d_axis.size() + kd] = pq[r];
  }
  return FluxMap(std::move(d_axis), std::move(q_axis), std::move(psi_d), std::move(psi_q));
}

int FluxMap::segment(const std::vector<double>& axis, double x) noexcept {
  const auto it = std::upper_bound(axis.begin() + 1, axis.end() - 1, x);
  return static_cast<int>(it - axis.begin()) - 1;
}

FluxMap::Cell FluxMap::locate(const core::Vec2& i) const noexcept {
  Cell c;
  c.kd = segment(i_d_, i[0]);
  c.kq = segment(i_q_, i[1]);
  const auto kd = static_cast<std::size_t>(c.kd), kq = static_cast<std::size_t>(c.kq);
  c.fd = (i[0] - i_d_[kd]) / (i_d_[kd + 1] - i_d_[kd]);
  c.fq = (i[1] - i_q_[kq]) / (i_q_[kq + 1] - i_q_[kq]);
  return c;
}

core::Vec2 FluxMap::flux(const core::Vec2& i_A) const noexcept {
  const Cell c = locate(i_A);
  auto bilinear = [&](const std::vector<double>& v) {
    const double v00 = at(v, c.kd, c.kq), v10 = at(v, c.kd + 1, c.kq);
    const double v01 = at(v, c.kd, c.kq + 1), v11 = at(v, c.kd + 1, c.kq + 1);
    return (1 - c.fq) * ((1 - c.fd) * v00 + c.fd * v10) + c.fq * ((1 - c.fd) * v01 + c.fd * v11);
  };
  return {bilinear(psi_d_), bilinear(psi_q_)};
}

core::Mat2 FluxMap::jacobian(const core::Vec2& i_A) const noexcept {
  const Cell c = locate(i_A);
  const double hd = i_d_[static_cast<std::size_t>(c.kd) + 1] - i_d_[static_cast<std::size_t>(c.kd)];
  const double hq = i_q_[static_cast<std::size_t>(c.kq) + 1] - i_q_[static_cast<std::size_t>(c.kq)];
  auto grad = [&](const std::vector<double>& v) {
    const double v00 = at(v, c.kd, c.kq), v10 = at(v, c.kd + 1, c.kq);
    const double v01 = at(v, c.kd, c.kq + 1), v11 = at(v, c.kd + 1, c.kq + 1);
    const double dd = ((1 - c.fq) * (v10 - v00) + c.fq * (v11 - v01)) / hd;
    const double dq = ((1 - c.fd) * (v01 - v00) + c.fd * (v11 - v10)) / hq;
    return std::pair{dd, dq};
  };
  const auto [dpd_did, dpd_diq] = grad(psi_d_);
  const auto [dpq_did, dpq_diq] = grad(psi_q_);
  core::Mat2 j;
  j << dpd_did, dpd_diq, dpq_did, dpq_diq;
  return j;
}

}  // namespace rpem::sim
