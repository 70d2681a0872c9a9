#include "rpem/core/thermal_stability.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "rpem/core/thermal_terms.hpp"

namespace rpem::core {

bool thermal_settles(const ThermalNetwork& n, const ThermalLoad& l) noexcept {
  const ThermalRates r = thermal_rates(n, l);
  ThermalMat m = ThermalMat::Identity();  // unused nodes: decoupled, stable
  for (int i = 0; i < n.nodes; ++i) {
    for (int j = 0; j < n.nodes; ++j) m(i, j) = -n.capacitance_J_per_K[i] * r.a(i, j);
  }
  const ThermalMat symmetric = 0.5 * (m + m.transpose());  // (14.27): symmetric but for rounding
  const Eigen::LLT<ThermalMat> llt(symmetric);
  if (llt.info() != Eigen::Success) return false;
  // Positive definite beyond rounding: a singular −C·A (no path to the coolant) leaves a last pivot of rounding's size.
  const double smallest_pivot = llt.matrixLLT().diagonal().minCoeff();
  return std::isfinite(smallest_pivot) && smallest_pivot * smallest_pivot > 1e-12 * symmetric.diagonal().maxCoeff();
}

double winding_conductance_to_coolant_W_per_K(const ThermalNetwork& n, const ThermalLoad& l) noexcept {
  ThermalMat m = ThermalMat::Identity();  // unused nodes: decoupled
  for (int i = 0; i < n.nodes; ++i) {
    m(i, i) = coolant_conductance_W_per_K(n, l, i);
    for (int j = 0; j < n.nodes; ++j) {
      if (j == i) continue;
      const double g = node_conductance_W_per_K(n, l, i, j);
      m(i, j) = -g;
      m(i, i) += g;
    }
  }
  const Eigen::LLT<ThermalMat> llt(m);
  if (llt.info() != Eigen::Success) return 0.0;
  const ThermalVec unit = ThermalVec::Unit(n.winding);
  const double resistance_K_per_W = unit.dot(llt.solve(unit));
  return std::isfinite(resistance_K_per_W) && resistance_K_per_W > 0.0 ? 1.0 / resistance_K_per_W : 0.0;
}

}  // namespace rpem::core
