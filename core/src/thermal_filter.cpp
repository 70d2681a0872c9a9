#include "rpem/core/thermal_filter.hpp"

#include <cmath>

namespace rpem::core {
namespace {

constexpr int kN = kMaxThermalNodes;
constexpr int kDynamic = 2 * kN;  ///< T and d: what the model moves and the filter estimates

}  // namespace

void ThermalFilter::reset(double t_C, double sigma_K) noexcept {
  set_temperatures(ThermalVec::Constant(t_C), ThermalMat::Identity() * (sigma_K * sigma_K));
}

void ThermalFilter::set_temperatures(const ThermalVec& t_C, const ThermalMat& p) noexcept {
  x_.setZero();
  x_.head<kN>() = t_C;
  p_.setZero();
  p_.topLeftCorner<kN, kN>() = p;
  for (int i = config_.network.nodes; i < kN; ++i) p_(i, i) = 0.0;
  p_.bottomRightCorner<kCalibrationStates, kCalibrationStates>().diagonal() = config_.calibration_sigma.cwiseAbs2();
  previous_terms_.setZero();
}

ThermalFilter::LossTerms ThermalFilter::loss_terms(const ThermalLoad& l) const noexcept {
  const ThermalNetwork& n = config_.network;
  LossTerms terms = LossTerms::Zero();
  terms(0, n.winding) = n.copper_scale * 1.5 * l.current_sq_A2 * n.copper.at(x_[n.winding]);
  for (int f = 0; f < kLossForms; ++f) terms.row(f + 1) = n.loss_at_base_W.row(f) * l.basis[static_cast<std::size_t>(f)];
  return terms;
}

void ThermalFilter::predict(const ThermalLoad& load) noexcept {
  if (!(load.dt_s > 0.0)) return;
  const ThermalNetwork& n = config_.network;
  const ThermalTransition tr = thermal_transition(n, load);
  // The disturbances' increments: their drift, and each modelled loss term's change times its uncertainty.
  const LossTerms terms = loss_terms(load);
  const LossTerms change = terms - previous_terms_;
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

  // x⁺ = F·x + [γ; 0; 0]: only the rows of T change, through G = [Φ Γ_d] acting on [T; d].
  Eigen::Matrix<double, kN, kDynamic> g;
  g << tr.phi, tr.gamma_d;
  x_.head<kN>() = g * x_.head<kDynamic>() + tr.gamma;
  // P⁺ = F·P·Fᵀ blockwise: the rows of T become G·P[T,d rows], then the columns of T likewise.
  const Eigen::Matrix<double, kN, kThermalStates> rows = g * p_.topRows<kDynamic>();
  p_.topRows<kN>() = rows;
  p_.leftCols<kN>() = rows.transpose();
  p_.topLeftCorner<kN, kN>() = rows.leftCols<kDynamic>() * g.transpose();
  ThermalMat q = ThermalMat::Zero();
  for (int i = 0; i < n.nodes; ++i) q(i, i) = config_.process_noise_K2_per_s[i];
  p_.topLeftCorner<kN, kN>() += 0.5 * load.dt_s * (tr.phi * q * tr.phi.transpose() + q);
  p_.block<kN, kN>(kN, kN).diagonal() += d_var;
  p_ = (0.5 * (p_ + p_.transpose())).eval();  // rounding must not make P asymmetric
}

ObservationResult ThermalFilter::observe(const ThermalObservation& o) noexcept {
  if (!all_finite(o.h, o.h_c, o.offset, o.value, o.variance) || !(o.variance > 0.0)) return ObservationResult::kRejectedInvalid;
  ThermalStateVec h = ThermalStateVec::Zero();
  h.head<kN>() = o.h;
  h.tail<kCalibrationStates>() = o.h_c;
  const ThermalStateVec ph = p_ * h;
  const double s = h.dot(ph) + o.variance;
  const double nu = o.value - h.dot(x_) - o.offset;
  innovation_ = nu;
  innovation_variance_ = s;
  if (nu * nu > config_.gate_sigma * config_.gate_sigma * s) return ObservationResult::kRejectedGate;
  // Schmidt's update: K = P·Hᵀ/s on T and d, zero on the calibration states (eq. 14.11). With a = P·Hᵀ:
  //   P_xx −= a_x·a_xᵀ/s,  P_xc −= a_x·a_cᵀ/s,  P_cc unchanged.
  const Eigen::Matrix<double, kDynamic, 1> a_x = ph.head<kDynamic>();
  x_.head<kDynamic>() += a_x * (nu / s);
  const ThermalStateVec a_x_full = (ThermalStateVec() << a_x, CalibrationVec::Zero()).finished();
  const ThermalStateMat update = a_x_full * ph.transpose() / s;
  p_ -= update;
  p_.bottomLeftCorner<kCalibrationStates, kDynamic>() = p_.topRightCorner<kDynamic, kCalibrationStates>().transpose();
  return ObservationResult::kAccepted;
}

double ThermalFilter::sigma_K(int node) const noexcept { return std::sqrt(std::max(p_(node, node), 0.0)); }

}  // namespace rpem::core
