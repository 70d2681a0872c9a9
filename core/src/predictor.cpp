#include "rpem/core/predictor.hpp"

namespace rpem::core {

Mat2 transition_matrix(const MachinePu& model, double omega_n, Discretization method, double dt_s, double n_pu) noexcept {
  const Mat2 a = system_matrix(model, omega_n, n_pu);
  if (method == Discretization::kExplicitEuler) {
    return Mat2::Identity() + dt_s * a;
  }
  return inverse2(Mat2::Identity() - 0.5 * dt_s * a) * (Mat2::Identity() + 0.5 * dt_s * a);
}

}  // namespace rpem::core
