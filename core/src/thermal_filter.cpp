#include "rpem/core/thermal_filter.hpp"

#include <cmath>

namespace rpem::core {

namespace {
constexpr int kN = kMaxThermalNodes;
}  // namespace

void ThermalFilter::reset(double t_C, double sigma_K) noexcept {
  ThermalMat p = ThermalMat::Identity() * (sigma_K * sigma_K);
  set_temperatures(ThermalVec::Constant(t_C), p);
}

void ThermalFilter::set_temperatures(const ThermalVec& t_C, const ThermalMat& p) noexcept {
  x_.setZero();
  x_.head<kN>() = t_C;
  p_.setZero();
  p_.topLeftCorner<kN, kN>() = p;
  for (int i = config_.network.nodes; i < kN; ++i) p_(i, i) = 0.0;
  previous_terms_.setZero();
}

Eigen::Matrix<double, kLossForms + 1, kMaxThermalNodes> ThermalFilter::loss_terms(const ThermalLoad& l) const noexcept {
  const ThermalNetwork& n = config_.network;
  Eigen::Matrix<double, kLossForms + 1, kMaxThermalNodes> terms = Eigen::Matrix<double, kLossForms + 1, kMaxThermalNodes>::Zero();
  terms(0, n.winding) = 1.5 * l.current_sq_A2 * n.copper.at(x_[n.winding]);
  for (int f = 0; f < kLossForms; ++f) terms.row(f + 1) = n.loss_at_base_W.row(f) * l.basis[static_cast<std::size_t>(f)];
  return terms;
}

void ThermalFilter::predict(const ThermalLoad& load) noexcept {
  if (!(load.dt_s > 0.0)) return;
  const ThermalNetwork& n = config_.network;
  const ThermalTransition tr = thermal_transition(n, load);
  // The disturbances' increments: their drift, and each modelled loss term's change times its uncertainty.
  const Eigen::Matrix<double, kLossForms + 1, kMaxThermalNodes> terms = loss_terms(load);
  const Eigen::Matrix<double, kLossForms + 1, kMaxThermalNodes> change = terms - previous_terms_;
  previous_terms_ = terms;
  ThermalVec d_var = config_.disturbance_W2_per_s * load.dt_s;
  for (int i = 0; i < n.nodes; ++i) {
    const double cu = config_.copper_rel_sigma * change(0, i);
    d_var[i] += cu * cu;
    for (int f = 0; f < kLossForms; ++f) {
      const double v = config_.loss_rel_sigma(f, i) * change(f + 1, i);
      d_var[i] += v * v;
    }
  }
  for (int i = n.nodes; i < kN; ++i) d_var[i] = 0.0;

  ThermalMat q = ThermalMat::Zero();
  for (int i = 0; i < n.nodes; ++i) q(i, i) = config_.process_noise_K2_per_s[i];
  // x⁺ = F·x + [γ; 0] with F = [Φ Γ_d; 0 I], blockwise.
  const ThermalVec t = x_.head<kN>(), d = x_.tail<kN>();
  x_.head<kN>() = tr.phi * t + tr.gamma + tr.gamma_d * d;
  ThermalStateMat f = ThermalStateMat::Identity();
  f.topLeftCorner<kN, kN>() = tr.phi;
  f.topRightCorner<kN, kN>() = tr.gamma_d;
  p_ = (f * p_ * f.transpose()).eval();
  p_.topLeftCorner<kN, kN>() += 0.5 * load.dt_s * (tr.phi * q * tr.phi.transpose() + q);
  p_.bottomRightCorner<kN, kN>().diagonal() += d_var;
}

ObservationResult ThermalFilter::observe(const ThermalObservation& o) noexcept {
  if (!all_finite(o.h, o.offset, o.value, o.variance) || !(o.variance > 0.0)) return ObservationResult::kRejectedInvalid;
  ThermalStateVec h = ThermalStateVec::Zero();
  h.head<kN>() = o.h;
  const ThermalStateVec ph = p_ * h;
  const double s = h.dot(ph) + o.variance;
  const double nu = o.value - o.h.dot(x_.head<kN>()) - o.offset;
  innovation_ = nu;
  innovation_variance_ = s;
  if (nu * nu > config_.gate_sigma * config_.gate_sigma * s) return ObservationResult::kRejectedGate;
  const ThermalStateVec k = ph / s;
  x_ += k * nu;
  const ThermalStateMat i_kh = ThermalStateMat::Identity() - k * h.transpose();
  p_ = (i_kh * p_ * i_kh.transpose()).eval();
  p_ += (o.variance * k) * k.transpose();
  return ObservationResult::kAccepted;
}

double ThermalFilter::sigma_K(int node) const noexcept { return std::sqrt(std::max(p_(node, node), 0.0)); }

}  // namespace rpem::core
