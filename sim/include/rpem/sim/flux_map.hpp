#pragma once
// Measured flux-linkage maps ψ_d(i_d, i_q), ψ_q(i_d, i_q) on a rectilinear grid (e.g. the Beckhoff
// AM8141 maps of data/beckhoff-am8141-flux-maps/, UltraZohm project, Apache-2.0), bilinear between grid
// points and linear beyond the grid edges.

#include <string>
#include <vector>

#include "rpem/core/types.hpp"

namespace rpem::sim {

class FluxMap {
 public:
  /// Grid axes (strictly increasing) and values, value(k_q, k_d) at index k_q·n_d + k_d.
  FluxMap(std::vector<double> i_d_A, std::vector<double> i_q_A, std::vector<double> psi_d_Wb, std::vector<double> psi_q_Wb);

  /// Reads a CSV with columns i_d_A, i_q_A, psi_d_Vs, psi_q_Vs (one row per grid point, any order).
  static FluxMap load_csv(const std::string& path);

  /// ψ(i) and its Jacobian ∂ψ/∂i (the differential inductance matrix) at i.
  [[nodiscard]] core::Vec2 flux(const core::Vec2& i_A) const noexcept;
  [[nodiscard]] core::Mat2 jacobian(const core::Vec2& i_A) const noexcept;

  /// Apparent inductances ψ_q/i_q and (ψ_d − ψ_d(0, 0))/i_d along an axis, for reports.
  [[nodiscard]] double magnet_flux_Wb() const noexcept { return flux(core::Vec2::Zero())[0]; }

  [[nodiscard]] const std::vector<double>& i_d_axis() const noexcept { return i_d_; }
  [[nodiscard]] const std::vector<double>& i_q_axis() const noexcept { return i_q_; }

 private:
  struct Cell {
    int kd, kq;
    double fd, fq;  ///< fractional position within the cell (may lie outside [0, 1] beyond the grid)
  };
  [[nodiscard]] static int segment(const std::vector<double>& axis, double x) noexcept;
  [[nodiscard]] Cell locate(const core::Vec2& i_A) const noexcept;
  [[nodiscard]] double at(const std::vector<double>& v, int kd, int kq) const noexcept {
    return v[static_cast<std::size_t>(kq) * i_d_.size() + static_cast<std::size_t>(kd)];
  }

  std::vector<double> i_d_, i_q_, psi_d_, psi_q_;
};

}  // namespace rpem::sim
