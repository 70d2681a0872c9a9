#include "indep_drive/flux_model.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "indep_drive/ipow.hpp"

namespace indep {

FluxModel::FluxModel(double l_d_H, double l_q_H, double current_scale_A, std::vector<PolyTerm> terms)
    : l_d_(l_d_H), l_q_(l_q_H), i_b_(current_scale_A), terms_(std::move(terms)) {
  if (!(l_d_ > 0.0) || !(l_q_ > 0.0) || !(i_b_ > 0.0)) throw std::invalid_argument("FluxModel: L and I_b must be > 0");
}

Vec2 FluxModel::flux(Vec2 i, double psi_m) const {
  Vec2 psi{psi_m + l_d_ * i.x, l_q_ * i.y};
  const double xd = i.x / i_b_, xq = i.y / i_b_;
  for (const PolyTerm& t : terms_) {
    if (t.m > 0) psi.x += t.b_Wb * t.m * ipow(xd, t.m - 1) * ipow(xq, t.n);
    if (t.n > 0) psi.y += t.b_Wb * t.n * ipow(xd, t.m) * ipow(xq, t.n - 1);
  }
  return psi;
}

Inductance2 FluxModel::inductance(Vec2 i) const {
  Inductance2 l{l_d_, 0.0, l_q_};
  const double xd = i.x / i_b_, xq = i.y / i_b_;
  for (const PolyTerm& t : terms_) {
    const double k = t.b_Wb / i_b_;
    if (t.m > 1) l.dd_H += k * t.m * (t.m - 1) * ipow(xd, t.m - 2) * ipow(xq, t.n);
    if (t.n > 1) l.qq_H += k * t.n * (t.n - 1) * ipow(xd, t.m) * ipow(xq, t.n - 2);
    if (t.m > 0 && t.n > 0) l.dq_H += k * t.m * t.n * ipow(xd, t.m - 1) * ipow(xq, t.n - 1);
  }
  return l;
}

double FluxModel::coenergy(Vec2 i, double psi_m) const {
  double w = psi_m * i.x + 0.5 * l_d_ * i.x * i.x + 0.5 * l_q_ * i.y * i.y;
  const double xd = i.x / i_b_, xq = i.y / i_b_;
  for (const PolyTerm& t : terms_) w += i_b_ * t.b_Wb * ipow(xd, t.m) * ipow(xq, t.n);
  return w;
}

Vec2 FluxModel::current(Vec2 psi, double psi_m, Vec2 guess) const {
  if (terms_.empty()) return {(psi.x - psi_m) / l_d_, psi.y / l_q_};
  Vec2 i = guess;
  const double tol = 1e-13 * (std::abs(psi_m) + psi.norm() + 1e-30);
  for (int it = 0; it < 50; ++it) {
    const Vec2 r = flux(i, psi_m) - psi;
    if (std::abs(r.x) + std::abs(r.y) <= tol) break;
    const Inductance2 l = inductance(i);
    const double det = l.dd_H * l.qq_H - l.dq_H * l.dq_H;
    const Vec2 step{(l.qq_H * r.x - l.dq_H * r.y) / det, (l.dd_H * r.y - l.dq_H * r.x) / det};
    i = i - step;
  }
  return i;
}

}  // namespace indep
