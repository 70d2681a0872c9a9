#include "rpem/sim/edge_integrator.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::sim {
namespace {

constexpr double kTimeTolerance_s = 1e-14;  ///< instants closer than this are one; the root's precision

LegCommand command_at(const LegSchedule& s, double t_s) noexcept {
  return t_s < s.switch_s ? s.first : (t_s < s.on_s ? LegCommand::kBlank : s.last);
}

/// The legs' switching instants inside the half period, in order (insertion: at most six); their number.
int order_edges(const std::array<LegSchedule, 3>& schedule, double half_s, std::array<double, 6>& edges) noexcept {
  int n_edges = 0;
  for (int x = 0; x < 3; ++x) {
    for (const double e : {schedule[x].switch_s, schedule[x].on_s}) {
      if (e >= half_s) continue;
      int k = n_edges++;
      for (; k > 0 && edges[k - 1] > e; --k) edges[k] = edges[k - 1];
      edges[k] = e;
    }
  }
  return n_edges;
}

}  // namespace

EdgeIntegrator::EdgeIntegrator(const InverterConfig& inverter, double tolerance) noexcept
    : inverter_(inverter),
      map_(tolerance),
      signs_matter_(inverter.dead_time_s > 0.0 || inverter.v_igbt_V != 0.0 || inverter.v_diode_V != 0.0) {}

void EdgeIntegrator::integrate(PmsmPlant& plant, bool rising, const Duties& duties, double u_dc_V) noexcept {
  if (plant.magnetics().uses_map()) {
    run(map_, plant, rising, duties, u_dc_V);
  } else {
    run(linear_, plant, rising, duties, u_dc_V);
  }
  plant.end_period();
  ++counters_.half_periods;
}

template <class Flow>
void EdgeIntegrator::run(Flow& flow, PmsmPlant& plant, bool rising, const Duties& duties, double u_dc_V) noexcept {
  const double half = inverter_.half_period_s();
  std::array<LegSchedule, 3> schedule;
  for (int x = 0; x < 3; ++x) schedule[x] = inverter_.schedule(rising, duties.d[x]);
  std::array<double, 6> edges{};  // the legs' switching instants in order
  const int n_edges = order_edges(schedule, half, edges);

  flow.prepare(plant);
  double t = 0.0;
  int next_edge = 0, events = 0;
  while (half - t > kTimeTolerance_s) {
    while (next_edge < n_edges && edges[next_edge] <= t + kTimeTolerance_s) ++next_edge;
    const double t_end = next_edge < n_edges ? edges[next_edge] : half;
    const double t_mid = 0.5 * (t + t_end);
    ++counters_.intervals;
    Legs legs;
    if (!signs_matter_) {  // an ideal inverter: the legs' voltages whatever the currents
      for (int x = 0; x < 3; ++x) legs.applied_V[x] = inverter_.leg_voltage(command_at(schedule[x], t_mid), 1, u_dc_V);
      flow.start(plant, core::clarke(legs.applied_V), t_end - t);
      const double h = flow.reach_s();
      flow.commit(plant, h);
      t += h;
      continue;
    }

    const int clamped = select_legs(schedule, plant.phase_currents(), t_mid, u_dc_V, legs);
    double h = t_end - t;
    if (clamped >= 0) {
      start_at_zero(flow, plant, clamped, legs, std::min(h, kClampStep_s));
      if (sign_[clamped] == 0) ++counters_.clamped_intervals;
    } else {
      flow.start(plant, core::clarke(legs.applied_V), h);
    }
    h = flow.reach_s();
    std::array<bool, 3> watched{};
    bool watch = false;  // a current whose sign selects its leg's voltage
    for (int x = 0; x < 3; ++x) {
      watched[x] = sign_[x] != 0 && legs.negative_V[x] != legs.positive_V[x];
      watch = watch || watched[x];
    }

    // The first zero crossing among them.
    double t_cross = h;
    const int crossing = watch && events < kMaxEvents ? first_watched_crossing(flow, watched, h, t_cross) : -1;
    flow.commit(plant, t_cross);
    t += t_cross;
    if (crossing >= 0) {
      // At zero: the next interval decides between the two signs and the clamp — unless another phase
      // is clamped already (then all three currents are at zero, and this one just changes sign).
      sign_[crossing] = clamped >= 0 && sign_[clamped] == 0 ? -sign_[crossing] : 0;
      ++events;
      ++counters_.zero_crossings;
    }
  }
  if (events >= kMaxEvents) ++counters_.event_limit_hits;
}

int EdgeIntegrator::select_legs(const std::array<LegSchedule, 3>& schedule, const core::Vec3& i, double t_mid, double u_dc_V,
                                Legs& legs) noexcept {
  int clamped = -1;
  for (int x = 0; x < 3; ++x) {
    const LegCommand c = command_at(schedule[x], t_mid);
    legs.positive_V[x] = inverter_.leg_voltage(c, 1, u_dc_V);
    legs.negative_V[x] = inverter_.leg_voltage(c, -1, u_dc_V);
    if (std::abs(i[x]) > kZeroCurrent_A) sign_[x] = i[x] > 0.0 ? 1 : -1;
    if (sign_[x] == 0 && clamped >= 0) sign_[x] = i[x] >= 0.0 ? 1 : -1;  // one clamp at a time
    if (sign_[x] == 0) clamped = x;
    legs.applied_V[x] = sign_[x] < 0 ? legs.negative_V[x] : legs.positive_V[x];
  }
  return clamped;
}

template <class Flow>
int EdgeIntegrator::first_watched_crossing(const Flow& flow, const std::array<bool, 3>& watched, double h_s,
                                           double& t_cross_s) const noexcept {
  int crossing = -1;
  const PhaseCurrents begin = flow.phases(0.0), end = flow.phases(h_s);
  for (int x = 0; x < 3; ++x) {
    if (!watched[x]) continue;
    const double tc = first_crossing(flow, x, begin, end, h_s);
    if (tc >= 0.0 && tc < t_cross_s) t_cross_s = tc, crossing = x;
  }
  return crossing;
}

template <class Flow>
void EdgeIntegrator::start_at_zero(Flow& flow, const PmsmPlant& plant, int x, Legs& legs, double h_s) noexcept {
  // The current's rate rises with the leg voltage; the positive current's voltage is the lower one.
  const double v_lo = legs.positive_V[x], v_hi = legs.negative_V[x];
  legs.applied_V[x] = v_lo;
  flow.start(plant, core::clarke(legs.applied_V), h_s);
  h_s = flow.reach_s();
  const double rate_lo = flow.phases(0.0).rate_A_s[x];
  if (rate_lo > 0.0 || v_hi == v_lo) {
    sign_[x] = rate_lo >= 0.0 ? 1 : -1;  // even the lower voltage drives the current up: it turns positive
    return;
  }
  double i_lo = flow.phases(h_s).i_A[x];
  legs.applied_V[x] = v_hi;
  flow.start(plant, core::clarke(legs.applied_V), h_s);
  if (flow.phases(0.0).rate_A_s[x] < 0.0) {
    sign_[x] = -1;
    return;
  }
  double i_hi = flow.phases(h_s).i_A[x];
  // Clamped: the voltage in [v_lo, v_hi] that brings the current back to zero at the sub-interval's
  // end — exact at the first step for constant inductances (the end current is affine in it), the
  // Illinois variant of regula falsi otherwise. If no voltage in the range does, the clamp ends inside
  // and the current leaves zero under the nearer bound.
  sign_[x] = 0;
  double a = v_lo, b = v_hi;
  double v = i_lo >= 0.0 ? v_lo : v_hi;
  for (int k = 0; k < 30 && i_lo < 0.0 && i_hi > 0.0; ++k) {
    v = (a * i_hi - b * i_lo) / (i_hi - i_lo);
    legs.applied_V[x] = v;
    flow.start(plant, core::clarke(legs.applied_V), h_s);
    const double i_v = flow.phases(h_s).i_A[x];
    if (std::abs(i_v) <= 0.1 * kZeroCurrent_A) return;
    if (i_v < 0.0) {
      a = v, i_lo = i_v, i_hi *= 0.5;
    } else {
      b = v, i_hi = i_v, i_lo *= 0.5;
    }
  }
  legs.applied_V[x] = v;
  flow.start(plant, core::clarke(legs.applied_V), h_s);
}

template <class Flow>
double EdgeIntegrator::first_crossing(const Flow& flow, int x, const PhaseCurrents& begin, const PhaseCurrents& end,
                                      double h_s) const noexcept {
  // g(t) = s·i_x(t) ≥ 0 on the current's side of zero; the crossing is where it falls below zero.
  const double s = sign_[x];
  const double g0 = s * begin.i_A[x], dg0 = s * begin.rate_A_s[x];
  const double g1 = s * end.i_A[x], dg1 = s * end.rate_A_s[x];
  auto g = [&](double t) { return s * flow.phases(t).i_A[x]; };
  // The turning point of g in [lo, hi], where g' has the sign of `rising` at lo and the other at hi.
  auto turning_point = [&](double lo, double hi, bool rising) {
    while (hi - lo > kTimeTolerance_s && hi - lo > 1e-9 * h_s) {
      const double mid = 0.5 * (lo + hi);
      ((s * flow.phases(mid).rate_A_s[x] > 0.0) == rising ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  double a = 0.0, b = h_s;  // g(a) ≥ 0 > g(b) once bracketed
  if (g0 < 0.0) {
    // Just past zero (a root's residual, or a sign decided at zero): a crossing if it keeps going,
    // else the first return after it has risen to its side.
    if (dg0 < 0.0) return 0.0;
    if (g1 >= 0.0 || dg1 >= 0.0) return -1.0;
    a = turning_point(0.0, h_s, true);
    if (g(a) <= 0.0) return 0.0;
  } else if (g1 >= 0.0) {
    // Same side at both ends: a crossing needs a turning point towards zero in between.
    if (!(dg0 < 0.0 && dg1 > 0.0)) return -1.0;
    b = turning_point(0.0, h_s, false);
    if (g(b) >= 0.0) return -1.0;
  }
  // Newton from the secant estimate, kept inside the bracket (bisection where it would leave it).
  double fa = g(a), fb = g(b);
  double t = a + (b - a) * fa / (fa - fb);
  for (int k = 0; k < 60; ++k) {
    const PhaseCurrents p = flow.phases(t);
    const double f = s * p.i_A[x], df = s * p.rate_A_s[x];
    (f >= 0.0 ? a : b) = t;
    double next = df != 0.0 ? t - f / df : 0.5 * (a + b);
    if (!(next > a && next < b)) next = 0.5 * (a + b);
    const bool done = std::abs(next - t) <= kTimeTolerance_s || b - a <= kTimeTolerance_s;
    t = next;
    if (done) break;
  }
  return t;
}

}  // namespace rpem::sim
