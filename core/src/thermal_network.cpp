#include "rpem/core/thermal_network.hpp"

#include <Eigen/LU>
#include <cmath>

#include "rpem/core/matrix_exponential.hpp"
#include "rpem/core/thermal_terms.hpp"

namespace rpem::core {
namespace {

// The loss forms (docs/derivations.md §14, "Losses"): B ∝ |ψ_s| at a given geometry, f ∝ |ω|.
double hysteresis(const LossPoint& p) noexcept { return p.f_rel * p.psi_rel * p.psi_rel; }
double eddy(const LossPoint& p) noexcept { return p.f_rel * p.f_rel * p.psi_rel * p.psi_rel; }
double magnet_eddy(const LossPoint& p) noexcept { return p.f_rel * p.f_rel * p.i_rel * p.i_rel; }

constexpr std::array<LossFormRow, kLossForms> kLossForms_{{
    {LossForm::kIronHysteresis, "iron_hysteresis", "k·(f/f_b)·(ψ_s/ψ_b)²", &hysteresis},
    {LossForm::kIronEddy, "iron_eddy", "k·(f/f_b)²·(ψ_s/ψ_b)²", &eddy},
    {LossForm::kMagnetEddy, "magnet_eddy", "k·(f/f_b)²·(|i|/i_b)²", &magnet_eddy},
}};

}  // namespace

const std::array<LossFormRow, kLossForms>& loss_forms() noexcept { return kLossForms_; }

std::array<double, kLossForms> loss_basis(const LossBase& base, const Vec2& i_dq_A, double omega_el_rad_s,
                                          const Vec2& psi_dq_Wb) noexcept {
  const LossPoint p{std::abs(omega_el_rad_s) / base.omega_el_rad_s, psi_dq_Wb.norm() / base.psi_Wb,
                    i_dq_A.norm() / base.current_A};
  std::array<double, kLossForms> b{};
  for (std::size_t f = 0; f < b.size(); ++f) b[f] = kLossForms_[f].basis(p);
  return b;
}

void LossAccumulator::add(const LossBase& base, double dt_s, const Vec2& i_dq_A, double omega_el_rad_s,
                          const Vec2& psi_dq_Wb, double coolant_C) noexcept {
  const std::array<double, kLossForms> b = loss_basis(base, i_dq_A, omega_el_rad_s, psi_dq_Wb);
  for (std::size_t f = 0; f < b.size(); ++f) basis_[f] += dt_s * b[f];
  current_sq_ += dt_s * i_dq_A.squaredNorm();
  convection_ += dt_s * std::sqrt(std::abs(omega_el_rad_s) / base.omega_el_rad_s);
  coolant_ += dt_s * coolant_C;
  dt_s_ += dt_s;
}

ThermalLoad LossAccumulator::take() noexcept {
  ThermalLoad l;
  l.dt_s = dt_s_;
  if (dt_s_ > 0.0) {
    const double w = 1.0 / dt_s_;
    l.current_sq_A2 = current_sq_ * w;
    l.convection_basis = convection_ * w;
    l.coolant_C = coolant_ * w;
    for (std::size_t f = 0; f < basis_.size(); ++f) l.basis[f] = basis_[f] * w;
  }
  *this = LossAccumulator{};
  return l;
}

ThermalRates thermal_rates(const ThermalNetwork& n, const ThermalLoad& l) noexcept {
  // Copper (eq. 14.2): (3/2)·R_ref·(1 + α·(T_w − T_ref))·i² = a + b·T_w.
  const DriftLaw& r = n.copper;
  const double copper_per_K = copper_loss_per_K(n, l);
  const double copper_at_0C = n.copper_scale * 1.5 * l.current_sq_A2 * r.value_ref * (1.0 - r.coeff_per_K * r.reference_C);
  ThermalRates out;
  for (int i = 0; i < n.nodes; ++i) {
    double loss = 0.0;
    for (int f = 0; f < kLossForms; ++f) loss += n.loss_at_base_W(f, i) * l.basis[static_cast<std::size_t>(f)];
    const double g_coolant = coolant_conductance_W_per_K(n, l, i);  // (14.1b)
    double g_total = g_coolant;
    for (int j = 0; j < n.nodes; ++j) {
      if (j == i) continue;
      const double g = node_conductance_W_per_K(n, l, i, j);  // (14.1b)
      out.a(i, j) = g;
      g_total += g;
    }
    out.a(i, i) = -g_total;
    out.u[i] = loss + g_coolant * l.coolant_C;
    if (i == n.winding) {
      out.a(i, i) += copper_per_K;
      out.u[i] += copper_at_0C;
    }
    const double inv_c = 1.0 / n.capacitance_J_per_K[i];
    out.a.row(i) *= inv_c;
    out.u[i] *= inv_c;
    out.coolant_per_s[i] = g_coolant * inv_c;
  }
  return out;
}

ThermalVec node_losses_W(const ThermalNetwork& n, const ThermalLoad& l, const ThermalVec& t_C) noexcept {
  ThermalVec p = ThermalVec::Zero();
  for (int i = 0; i < n.nodes; ++i) {
    for (int f = 0; f < kLossForms; ++f) p[i] += n.loss_at_base_W(f, i) * l.basis[static_cast<std::size_t>(f)];
  }
  p[n.winding] += n.copper_scale * 1.5 * l.current_sq_A2 * n.copper.at(t_C[n.winding]);
  return p;
}

namespace {

/// e^X and φ₁(X) of a block-diagonal X whose nodes past `nodes` are zero rows and columns (thermal_rates):
/// for a 2-node network the series on its 2×2 block, the unused block's e^0 = φ₁(0) = I — the same matrices
/// as the 4×4 series at an eighth of its products (a third less time for `rpem thermal fit`). Three nodes
/// keep the 4×4 series: Eigen vectorises 4×4 products and not 3×3 ones, and the 3×3 block measured 15 %
/// slower (docs/benchmarks.md, "Thermal fusion").
ExponentialPair<kMaxThermalNodes> exponential_of_nodes_in_use(const ThermalMat& x, int nodes) noexcept {
  if (nodes != 2) return exponential_and_phi1<kMaxThermalNodes>(x);
  ExponentialPair<kMaxThermalNodes> out{ThermalMat::Identity(), ThermalMat::Identity()};
  const ExponentialPair<2> e = exponential_and_phi1<2>(x.topLeftCorner<2, 2>());
  out.exp.topLeftCorner<2, 2>() = e.exp;
  out.phi1.topLeftCorner<2, 2>() = e.phi1;
  return out;
}

}  // namespace

ThermalTransition thermal_transition(const ThermalNetwork& n, const ThermalRates& r, double dt_s) noexcept {
  const ExponentialPair<kMaxThermalNodes> e = exponential_of_nodes_in_use(r.a * dt_s, n.nodes);
  ThermalTransition t;
  t.phi = e.exp;
  const ThermalMat integral = dt_s * e.phi1;  // ∫₀^Δt e^{A·s} ds
  t.gamma = integral * r.u;
  t.gamma_d = integral * n.capacitance_J_per_K.cwiseInverse().asDiagonal();
  for (int i = n.nodes; i < kMaxThermalNodes; ++i) t.gamma_d.col(i).setZero();  // unused nodes take no heat
  return t;
}

ThermalTransition thermal_transition(const ThermalNetwork& n, const ThermalLoad& l) noexcept {
  return thermal_transition(n, thermal_rates(n, l), l.dt_s);
}

ThermalVec thermal_steady_state(const ThermalNetwork& n, const ThermalLoad& l) noexcept {
  ThermalRates r = thermal_rates(n, l);
  for (int i = n.nodes; i < kMaxThermalNodes; ++i) {  // unused nodes: T_i = T_coolant
    r.a(i, i) = -1.0;
    r.u[i] = l.coolant_C;
  }
  return r.a.partialPivLu().solve(-r.u);
}

}  // namespace rpem::core
