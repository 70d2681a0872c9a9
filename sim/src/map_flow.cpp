#include "rpem/sim/map_flow.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::sim {
namespace {

constexpr double kMinStep_s = 1e-12;  ///< accepted whatever its error (a kink of the bilinear map)
constexpr double kRejected = 1e300;   ///< the error ratio of a step whose estimate is not finite

}  // namespace

void MapFlow::prepare(const PmsmPlant& plant) noexcept {
  plant_ = &plant;
  omega_ = plant.period_speed();
}

core::Vec2 MapFlow::rate(double t_s, const core::Vec2& psi, core::Vec2& i_flux) const noexcept {
  const PmsmPlant& p = *plant_;
  i_flux = p.magnetics().current(psi, i_flux);
  const core::Vec2 u_dq = core::park(u_ab_V_, core::compose(r0_, rotation_by(omega_ * t_s)));
  return p.derivative(psi, p.stator_current(psi, i_flux, omega_), u_dq, omega_);
}

void MapFlow::start(const PmsmPlant& plant, const core::Vec2& u_ab_V, double h_max_s) noexcept {
  plant_ = &plant;
  r0_ = plant.rotation();
  u_ab_V_ = u_ab_V;
  Node n;
  n.psi_Wb = plant.state().psi_Wb;
  n.i_flux_A = plant.magnetising_current();
  n.rate_V = rate(0.0, n.psi_Wb, n.i_flux_A);
  nodes_[0] = n;
  count_ = 0;
  const double scale_Wb = plant.parameters().psi_m_Wb;
  while (count_ < kMaxSteps && n.t_s < h_max_s) {
    const double left = h_max_s - n.t_s;
    const double h = h_next_s_ < left - kMinStep_s ? h_next_s_ : left;  // no sliver left over
    // Bogacki–Shampine 3(2): k1 = f(t, y), k2 at t + h/2, k3 at t + 3h/4, k4 = f(t + h, y₁) (FSAL).
    const core::Vec2& k1 = n.rate_V;
    core::Vec2 i2 = n.i_flux_A;
    const core::Vec2 k2 = rate(n.t_s + 0.5 * h, n.psi_Wb + (0.5 * h) * k1, i2);
    core::Vec2 i3 = i2;
    const core::Vec2 k3 = rate(n.t_s + 0.75 * h, n.psi_Wb + (0.75 * h) * k2, i3);
    Node next;
    next.t_s = n.t_s + h;
    next.psi_Wb = n.psi_Wb + h * ((2.0 / 9.0) * k1 + (1.0 / 3.0) * k2 + (4.0 / 9.0) * k3);
    next.i_flux_A = i3;
    next.rate_V = rate(next.t_s, next.psi_Wb, next.i_flux_A);
    const core::Vec2 error = h * ((-5.0 / 72.0) * k1 + (1.0 / 12.0) * k2 + (1.0 / 9.0) * k3 - 0.125 * next.rate_V);
    double ratio = 0.0;  // error / allowed, worst axis (not finite: rejected)
    for (int j = 0; j < 2; ++j) {
      const double r = std::abs(error[j]) / (tolerance_ * (scale_Wb + std::abs(next.psi_Wb[j])));
      ratio = std::max(ratio, std::isfinite(r) ? r : kRejected);
    }
    const double grow = ratio > 0.0 ? 0.9 / std::cbrt(ratio) : 5.0;
    const double proposed = h * std::clamp(grow, 0.2, 5.0);
    // A step cut short by the interval's end does not shrink the next proposal.
    h_next_s_ = ratio <= 1.0 && h < h_next_s_ ? std::max(h_next_s_, proposed) : proposed;
    if (ratio > 1.0 && h > kMinStep_s) {
      ++rejected_;
      continue;
    }
    ++accepted_;
    n = next;
    nodes_[static_cast<std::size_t>(++count_)] = n;
  }
}

MapFlow::Node MapFlow::at(double t_s) const noexcept {
  if (count_ == 0 || t_s <= 0.0) return nodes_[0];
  int k = 1;
  while (k < count_ && nodes_[static_cast<std::size_t>(k)].t_s < t_s) ++k;
  const Node& a = nodes_[static_cast<std::size_t>(k - 1)];
  const Node& b = nodes_[static_cast<std::size_t>(k)];
  if (t_s >= b.t_s) return b;
  const double h = b.t_s - a.t_s, s = (t_s - a.t_s) / h, s2 = s * s, s3 = s2 * s;
  Node n;
  n.t_s = t_s;
  // Cubic Hermite through both ends' values and rates.
  n.psi_Wb = (2 * s3 - 3 * s2 + 1) * a.psi_Wb + (h * (s3 - 2 * s2 + s)) * a.rate_V + (3 * s2 - 2 * s3) * b.psi_Wb +
             (h * (s3 - s2)) * b.rate_V;
  n.rate_V = ((6 * s2 - 6 * s) / h) * (a.psi_Wb - b.psi_Wb) + (3 * s2 - 4 * s + 1) * a.rate_V + (3 * s2 - 2 * s) * b.rate_V;
  n.i_flux_A = plant_->magnetics().current(n.psi_Wb, a.i_flux_A + s * (b.i_flux_A - a.i_flux_A));
  return n;
}

PhaseCurrents MapFlow::phases(double t_s) const noexcept {
  const PmsmPlant& p = *plant_;
  const Node n = at(t_s);
  // i_s = i(ψ) + (ω/R_fe)·J·ψ, so di_s/dt = (∂ψ/∂i)⁻¹·dψ/dt + (ω/R_fe)·J·dψ/dt.
  const core::Vec2 di_flux = core::inverse2(p.magnetics().map()->jacobian(n.i_flux_A)) * n.rate_V;
  const core::Vec2 i_s = p.stator_current(n.psi_Wb, n.i_flux_A, omega_);
  const core::Vec2 di_s = p.stator_current(n.rate_V, di_flux, omega_);  // the same map, applied to the rates
  return phase_currents(i_s, di_s, core::compose(r0_, rotation_by(omega_ * t_s)), omega_);
}

void MapFlow::commit(PmsmPlant& plant, double t_s) const noexcept {
  const Node n = at(t_s);
  plant.move_to(n.psi_Wb, n.i_flux_A, t_s);
}

}  // namespace rpem::sim
