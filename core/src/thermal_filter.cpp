#include "rpem/core/thermal_filter.hpp"

#include <cmath>

#include "rpem/core/thermal_terms.hpp"

namespace rpem::core {
namespace {

constexpr int kN = kMaxThermalNodes;
constexpr int kDynamic = kDynamicThermalStates;
constexpr int kCoolant = kDynamic + static_cast<int>(Calibration::kCoolantError);

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

void ThermalFilter::predict(const ThermalLoad& load, const ThermalRates& rates) noexcept {
  if (!(load.dt_s > 0.0)) return;
  const ThermalNetwork& n = config_.network;
  const ThermalTransition tr = thermal_transition(n, rates, load.dt_s);
  // The disturbances' increments: their drift, and each modelled loss term's change times its uncertainty.
  const LossTerms terms = loss_terms(load);
  const LossTerms change = terms - previous_terms_;
  previous_terms_ = terms;
  // The Gauss–Markov decay a = e^{−Δt/τ_d} and the drift's variance over the step (eq. 14.19);
  // τ_d = ∞ is the walk exactly (a = 1, q_d·Δt).
  ThermalVec decay = ThermalVec::Ones();
  ThermalVec d_var = ThermalVec::Zero();
  for (int i = 0; i < n.nodes; ++i) {
    const double tau = config_.disturbance_time_constant_s[i];
    if (std::isinf(tau)) {
      d_var[i] = config_.disturbance_W2_per_s[i] * load.dt_s;
    } else {
      decay[i] = std::exp(-load.dt_s / tau);
      d_var[i] = config_.disturbance_W2_per_s[i] * 0.5 * tau * -std::expm1(-2.0 * load.dt_s / tau);
    }
  }
  for (int i = 0; i < n.nodes; ++i) {
    const double cu = config_.copper_rel_sigma * change(0, i);
    d_var[i] += cu * cu;
    for (int f = 0; f < kLossForms; ++f) {
      const double v = config_.loss_rel_sigma(f, i) * change(f + 1, i);
      d_var[i] += v * v;
    }
  }
  for (int i = n.nodes; i < kN; ++i) d_var[i] = 0.0;

  // x⁺ = F·x + [γ; 0; 0]: only the rows of T change, through G = [Φ Γ_d] acting on [T; d] and b = Γ_d·g_c on the
  // coolant's error (eq. 14.29), whose mean is zero (a consider state), so that it moves only the covariance.
  Eigen::Matrix<double, kN, kDynamic> g;
  g << tr.phi, tr.gamma_d;
  ThermalVec g_c = ThermalVec::Zero();
  for (int i = 0; i < n.nodes; ++i) g_c[i] = coolant_conductance_W_per_K(n, load, i);
  const ThermalVec b = tr.gamma_d * g_c;
  x_.head<kN>() = g * x_.head<kDynamic>() + tr.gamma;  // a product that may alias: Eigen evaluates it first
  x_.segment<kN>(kN).array() *= decay.array();         // eq. 14.20
  transition_ = tr;
  decay_ = decay;
  predicted_ = true;
  // P⁺ = F·P·Fᵀ + Q_d blockwise (docs/derivations.md §14, eq. 14.12, 14.21, 14.29): c is constant but for e_c's
  // walk and d scales by A, so the rows of T become G·P[T,d rows] + b·P[e_c row] (from the prior P), the rows and
  // columns of d scale by A, and the T–d block is then that times A. Small fixed sizes: coefficient-wise products,
  // no blocking.
  Eigen::Matrix<double, kN, kThermalStates> rows = g.lazyProduct(p_.topRows<kDynamic>());
  rows += b * p_.row(kCoolant);
  ThermalMat p_tt = rows.leftCols<kDynamic>().lazyProduct(g.transpose()) + rows.col(kCoolant) * b.transpose();
  // P_dd(i, j)·(a_i·a_j): the same product for (i, j) and (j, i), so P_dd stays exactly symmetric; P_cd follows P_dc.
  rows.middleCols<kN>(kN) *= decay.asDiagonal();
  p_.block<kN, kN>(kN, kN).array() *= (decay * decay.transpose()).array();
  p_.block<kN, kCalibrationStates>(kN, kDynamic) = decay.asDiagonal() * p_.block<kN, kCalibrationStates>(kN, kDynamic);
  p_.block<kCalibrationStates, kN>(kDynamic, kN) = p_.block<kN, kCalibrationStates>(kN, kDynamic).transpose();
  p_.topRows<kN>() = rows;
  p_.leftCols<kN>() = rows.transpose();
  ThermalVec q = ThermalVec::Zero();  // Q_T, on the nodes in use
  for (int i = 0; i < n.nodes; ++i) q[i] = config_.process_noise_K2_per_s[i];
  p_tt += 0.5 * load.dt_s * ((tr.phi * q.asDiagonal()).lazyProduct(tr.phi.transpose()) + ThermalMat(q.asDiagonal()));
  // Rounding must not make P asymmetric: P_TT is the only block not symmetric by construction.
  p_.topLeftCorner<kN, kN>() = 0.5 * (p_tt + p_tt.transpose());
  p_.block<kN, kN>(kN, kN).diagonal() += d_var;
  if (coolant_seen_) p_(kCoolant, kCoolant) += config_.coolant_drift_K2_per_s * load.dt_s;  // eq. 14.29
}

void ThermalFilter::coolant_read() noexcept {
  p_.row(kCoolant).setZero();
  p_.col(kCoolant).setZero();
  coolant_seen_ = true;
}

ThermalStateVec ThermalFilter::cross_covariance(const ThermalObservation& o) const noexcept {
  // H = [h, h_d, h_c]: h_d is zero but for a sensor that sees the winding's rate (eq. 14.22).
  return p_.leftCols<kN>().lazyProduct(o.h) + p_.middleCols<kN>(kN).lazyProduct(o.h_d) +
         p_.rightCols<kCalibrationStates>().lazyProduct(o.h_c);
}

double ThermalFilter::innovation_variance(const ThermalObservation& o, const ThermalStateVec& a) const noexcept {
  // The bilinear term b·δT_i·δc_k over the Gaussian prior (eq. 14.10a): mean b·P_ik, variance b²·(P_ii·P_kk + P_ik²),
  // no covariance with the state (third moments vanish), so a is unchanged.
  const int k = kDynamic + static_cast<int>(o.bilinear_state), i = o.bilinear_node;
  const double p_ik = p_(i, k);
  return o.h.dot(a.head<kN>()) + o.h_d.dot(a.segment<kN>(kN)) + o.h_c.dot(a.tail<kCalibrationStates>()) + o.variance +
         o.bilinear * o.bilinear * (p_(i, i) * p_(k, k) + p_ik * p_ik);
}

double ThermalFilter::innovation_variance(const ThermalObservation& o) const noexcept {
  return innovation_variance(o, cross_covariance(o));
}

ObservationResult ThermalFilter::observe(const ThermalObservation& o) noexcept {
  if (!all_finite(o.h, o.h_d, o.h_c, o.offset, o.value, o.variance, o.bilinear) || !(o.variance > 0.0) ||
      o.bilinear_node < 0 || o.bilinear_node >= kN)
    return ObservationResult::kRejectedInvalid;
  const ThermalStateVec a = cross_covariance(o);
  const double s = innovation_variance(o, a);
  const double p_ik = p_(o.bilinear_node, kDynamic + static_cast<int>(o.bilinear_state));
  const double nu = o.value - o.h.dot(x_.head<kN>()) - o.h_d.dot(x_.segment<kN>(kN)) -
                    o.h_c.dot(x_.tail<kCalibrationStates>()) - o.offset - o.bilinear * p_ik;
  innovation_ = nu;
  innovation_variance_ = s;
  if (nu * nu > config_.gate_sigma * config_.gate_sigma * s) return ObservationResult::kRejectedGate;
  // Schmidt's update: K = a_x/s on T and d, zero on the calibration states (eq. 14.11):
  //   P_xx −= a_x·a_xᵀ/s,  P_xc −= a_x·a_cᵀ/s,  P_cc unchanged.
  // Only the rows of x change; each column j loses (a_x·a_j)·(1/s), the same product for (i, j) and (j, i),
  // so P_xx stays exactly symmetric, and P_cx is P_xc's transpose.
  const Eigen::Matrix<double, kDynamic, 1> a_x = a.head<kDynamic>();
  x_.head<kDynamic>() += a_x * (nu / s);
  const double inv_s = 1.0 / s;
  for (int j = 0; j < kThermalStates; ++j) p_.col(j).head<kDynamic>() -= (a_x * a[j]) * inv_s;
  p_.bottomLeftCorner<kCalibrationStates, kDynamic>() = p_.topRightCorner<kDynamic, kCalibrationStates>().transpose();
  return ObservationResult::kAccepted;
}

void ThermalFilter::withdraw_to(const ThermalVec& t_C, const ThermalVec& d_W) noexcept {
  ThermalVec delta = t_C - x_.head<kN>();
  for (int i = config_.network.nodes; i < kN; ++i) delta[i] = 0.0;  // unused nodes stay
  x_.head<kN>() += delta;
  for (int i = 0; i < config_.network.nodes; ++i) x_[kN + i] = d_W[i];
  p_.topLeftCorner<kN, kN>() += delta * delta.transpose();  // a rank-one PSD term on T: P stays PSD
}

void ThermalFilter::advance_open_loop(ThermalVec& t_C, ThermalVec& d_W) const noexcept {
  if (!predicted_) return;
  t_C = transition_.phi * t_C + transition_.gamma + transition_.gamma_d * d_W;  // Eigen evaluates before assigning
  d_W.array() *= decay_.array();
}

double ThermalFilter::sigma_K(int node) const noexcept { return std::sqrt(std::max(p_(node, node), 0.0)); }

}  // namespace rpem::core
