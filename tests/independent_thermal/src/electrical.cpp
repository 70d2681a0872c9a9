#include "indep_thermal/electrical.hpp"

#include <algorithm>
#include <cmath>

#include "indep_thermal/materials.hpp"
#include "indep_thermal/pi.hpp"

namespace indep_thermal {

namespace {

// |u|² − U² of the configured machine's steady state as a quadratic a·i_d² + b·i_d + c in i_d.
struct Quadratic {
  double a, b, c;
  [[nodiscard]] double discriminant() const { return b * b - 4.0 * a * c; }
  [[nodiscard]] double at(double x) const { return (a * x + b) * x + c; }
};

Quadratic voltage_excess(const Machine& m, double omega, double i_q, double u_max) {
  const double r = m.r_s_Ohm;
  const double uq0 = r * i_q + omega * m.psi_m_Wb;  // u_q without the i_d term
  const double ud0 = -omega * m.l_q_H * i_q;        // u_d without the i_d term
  return {r * r + omega * omega * m.l_d_H * m.l_d_H, 2.0 * (r * ud0 + omega * m.l_d_H * uq0),
          ud0 * ud0 + uq0 * uq0 - u_max * u_max};
}

}  // namespace

DqVoltage steady_state_voltage(const Parameters& p, const OperatingPoint& op, double t_winding_C, double t_rotor_C) {
  const double f = std::abs(op.omega_el_rad_s) / (2.0 * kPi);
  const double r = copper_resistance_Ohm(p, t_winding_C) * ac_resistance_factor(p, f);
  const double w = op.omega_el_rad_s;
  return {r * op.i_d_A - w * p.l_q_H * op.i_q_A, r * op.i_q_A + w * (p.l_d_H * op.i_d_A + magnet_flux_Wb(p, t_rotor_C))};
}

double mtpa_i_d_A(double psi_m_Wb, double l_d_H, double l_q_H, double i_q_A) {
  const double dl = l_q_H - l_d_H;
  if (dl <= 0.0) return 0.0;
  return (psi_m_Wb - std::sqrt(psi_m_Wb * psi_m_Wb + 4.0 * dl * dl * i_q_A * i_q_A)) / (2.0 * dl);
}

OperatingPoint drive_currents(const Machine& m, const Parameters& p, const Demand& demand, double t_winding_sensor_C) {
  OperatingPoint op;
  op.omega_el_rad_s = demand.speed_rpm * 2.0 * kPi / 60.0 * m.pole_pairs;
  const double derate = std::clamp((p.derate_end_C - t_winding_sensor_C) / (p.derate_end_C - p.derate_start_C), 0.0, 1.0);
  double i_q = demand.i_q_A * derate;
  const double i_max = p.current_limit_rel * m.peak_current_A();
  double i_d = 0.0;
  if (demand.i_d_given) {
    i_d = demand.i_d_A;
  } else {
    const double u_max = p.voltage_limit_rel * m.peak_voltage_V();
    const double w = op.omega_el_rad_s;
    i_d = mtpa_i_d_A(m.psi_m_Wb, m.l_d_H, m.l_q_H, i_q);
    Quadratic q = voltage_excess(m, w, i_q, u_max);
    if (q.at(i_d) > 0.0) {
      if (q.discriminant() < 0.0) {
        // No i_d meets the limit at this i_q: lower |i_q| (bisection) to the largest that can, if any.
        double lo = 0.0;
        double hi = 1.0;
        if (voltage_excess(m, w, 0.0, u_max).discriminant() >= 0.0) {
          for (int k = 0; k < 60; ++k) {
            const double mid = 0.5 * (lo + hi);
            (voltage_excess(m, w, mid * i_q, u_max).discriminant() >= 0.0 ? lo : hi) = mid;
          }
        }
        i_q *= lo;
        q = voltage_excess(m, w, i_q, u_max);
        i_d = -q.b / (2.0 * q.a);  // the least voltage (the limit exactly, unless even i_q = 0 exceeds it)
      } else {
        const double root = std::sqrt(q.discriminant());
        const double upper = (-q.b + root) / (2.0 * q.a);
        const double lower = (-q.b - root) / (2.0 * q.a);
        i_d = i_d > upper ? upper : lower;
      }
    }
  }
  i_d = std::clamp(i_d, -i_max, i_max);
  const double i_q_max = std::sqrt(std::max(0.0, i_max * i_max - i_d * i_d));
  op.i_d_A = i_d;
  op.i_q_A = std::clamp(i_q, -i_q_max, i_q_max);
  return op;
}

}  // namespace indep_thermal
