// Sampled means (docs/derivations.md §11): a drive averages one current sample per control cycle, not the
// current, while the voltage it holds in the stator frame turns by −ω·τ in the rotor frame across the cycle.
// The data here are the exact periodic solution of the machine equations over one cycle (complex dq,
// j = J, L_d = L_q = L; independent of the estimator's second-order correction):
//   L·di/dt = V·e^{−jωτ} − (R + jωL)·i − jωψm,   i(T) = i(0)
//   i(τ) = i_c + (V/R)·e^{−jωτ} + C·e^{−zτ},   z = R/L + jω,   i_c = −jωψm/(R + jωL),
//   C = (V/R)·(e^{−jωT} − 1)/(1 − e^{−zT})
// whose cycle mean ī obeys the steady state ū = (R + jωL)·ī + jωψm exactly, ū = V·e^{−jωT/2}·sinc(ωT/2).
// The drive reports i(a·T) and ū. A VESC-sized machine (config/vesc-6374-outrunner.yaml's values restated)
// at 6000 rpm under T = 80 µs: ω·T = 0.35.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "rpem/core/averaged_estimator.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

using cplx = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;
constexpr double kR_Ohm = 0.025, kL_H = 20e-6, kPsi_Wb = 0.004633, kT_s = 80e-6, kIq_A = 30.0;
constexpr int kPolePairs = 7;
const double kOmega = 6000.0 / 60.0 * 2.0 * kPi * kPolePairs;

MachineSi vesc_machine() {
  MachineSi m;
  m.rated = {34.0, 40.0, 6000.0, kPolePairs};
  m.r_s_Ohm = kR_Ohm;
  m.psi_m_Wb = kPsi_Wb;
  m.l_d_H = m.l_q_H = kL_H;
  return m;
}

EstimatorSettings settings(double control_period_s, double sample_at) {
  EstimatorSettings s = test::paper_settings();
  s.psi_m_min_speed_rpm = 600.0;
  s.r_s_max_speed_rpm = 60.0;
  s.psi_m_min_Wb = 0.5 * kPsi_Wb;
  s.psi_m_max_Wb = 1.5 * kPsi_Wb;
  s.r_s_min_Ohm = 0.5 * kR_Ohm;
  s.r_s_max_Ohm = 2.0 * kR_Ohm;
  s.initial_psi_m_Wb = 0.95 * kPsi_Wb;  // ψm adapts from 5 % low; R_s is scheduled out at speed
  s.initial_r_s_Ohm = kR_Ohm;
  s.averaged.control_period_s = control_period_s;
  s.averaged.current_sample_at = sample_at;
  return s;
}

/// What the drive reports in steady state: the current sampled at a·T and the cycle's mean voltage.
struct Reported {
  cplx i_sample_A, u_mean_V;
};

Reported exact_cycle(double a) {
  const cplx j(0.0, 1.0);
  const cplx i_mean(0.0, kIq_A);
  const cplx u_mean = (kR_Ohm + j * kOmega * kL_H) * i_mean + j * kOmega * kPsi_Wb;
  const double x = 0.5 * kOmega * kT_s;
  const cplx v = u_mean * std::exp(j * x) * (x / std::sin(x));
  const cplx z = kR_Ohm / kL_H + j * kOmega;
  const cplx i_c = -j * kOmega * kPsi_Wb / (kR_Ohm + j * kOmega * kL_H);
  const cplx c = (v / kR_Ohm) * (std::exp(-j * kOmega * kT_s) - 1.0) / (1.0 - std::exp(-z * kT_s));
  const double tau = a * kT_s;
  return {i_c + (v / kR_Ohm) * std::exp(-j * kOmega * tau) + c * std::exp(-z * tau), u_mean};
}

/// ψ̂m / ψm − 1 after 10 s of 5 ms windows of the reported values.
double psi_m_bias(double control_period_s, double sample_at) {
  AveragedDriveEstimator est(vesc_machine(), settings(control_period_s, sample_at));
  const Reported r = exact_cycle(sample_at);
  AveragedSample s;
  s.i_dq_A = Vec2(r.i_sample_A.real(), r.i_sample_A.imag());
  s.u_dq_V = Vec2(r.u_mean_V.real(), r.u_mean_V.imag());
  s.omega_el_rad_s = kOmega;
  s.u_dc_V = 48.0;
  for (int k = 1; k <= 2000; ++k) {
    s.t_start_ns = (k - 1) * 5'000'000LL;
    s.t_ns = k * 5'000'000LL;
    (void)est.step(s);
  }
  return est.psi_m_Wb() / kPsi_Wb - 1.0;
}

TEST(AveragedCycleSampling, ExactCycleMeanObeysTheSteadyState) {
  // The generator's own check: the mean of i(τ) over the cycle (Simpson, 2000 intervals) is ī.
  cplx sum = 0.0;
  const int n = 2000;
  for (int k = 0; k <= n; ++k) {
    const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    sum += w * exact_cycle(static_cast<double>(k) / n).i_sample_A;
  }
  const cplx mean = sum / (3.0 * n);
  EXPECT_NEAR(mean.real(), 0.0, 1e-9);
  EXPECT_NEAR(mean.imag(), kIq_A, 1e-9);
  // and it is periodic
  EXPECT_NEAR(std::abs(exact_cycle(1.0).i_sample_A - exact_cycle(0.0).i_sample_A), 0.0, 1e-9);
}

TEST(AveragedCycleSampling, UncorrectedBiasIsTheDerivedOne) {
  // ψ̂m/ψm − 1 ≈ −c·(ωT)²·(1 + 2·R·i_q/(ω·ψm)), c = (a − ½)²/2 − 1/24: −1.11 % at a = 0, +0.55 % at a = ½.
  // Second order in ωT = 0.35; the rest (0.6 % of it here) is held to 2 %.
  const double wt2 = kOmega * kT_s * kOmega * kT_s;
  const double load = 1.0 + 2.0 * kR_Ohm * kIq_A / (kOmega * kPsi_Wb);
  for (double a : {0.0, 0.5}) {
    const double c = 0.5 * (a - 0.5) * (a - 0.5) - 1.0 / 24.0;
    const double derived = -c * wt2 * load;
    EXPECT_NEAR(psi_m_bias(0.0, a), derived, 0.02 * std::abs(derived)) << "a=" << a;
  }
}

TEST(AveragedCycleSampling, CorrectionRemovesTheCycleSamplingBias) {
  // With the drive's control period configured the bias falls to third order in ωT, wherever the drive
  // samples: 0.006 % at a = 0 and ½, 0.024 % at a = 0.8 (from −1.1 % and +0.55 %); held below 0.03 %.
  for (double a : {0.0, 0.25, 0.5, 0.8}) {
    EXPECT_LT(std::abs(psi_m_bias(kT_s, a)), 3e-4) << "a=" << a;
  }
}

/// ψ̂m / ψm − 1 when the drive reports, instead of the mean, the command it computed from a current sample in
/// that sample's frame and holds from `delay_periods`·T later for one period (VESC's firmware: ½, the
/// sample then in the middle of the hold, a = 1 − delay). The command in the sample's frame is the held
/// vector turned back by the rotor's advance over the delay: v·e^{jωδ}.
double psi_m_bias_of_command(double delay_periods, bool voltage_is_command) {
  EstimatorSettings st = settings(kT_s, 1.0 - delay_periods);
  st.averaged.voltage_is_command = voltage_is_command;
  st.extensions.delay_s = delay_periods * kT_s;
  AveragedDriveEstimator est(vesc_machine(), st);
  const Reported r = exact_cycle(1.0 - delay_periods);
  const cplx j(0.0, 1.0);
  const double x = 0.5 * kOmega * kT_s;
  const cplx command = r.u_mean_V * std::exp(j * x) * (x / std::sin(x)) * std::exp(j * kOmega * delay_periods * kT_s);
  AveragedSample s;
  s.i_dq_A = Vec2(r.i_sample_A.real(), r.i_sample_A.imag());
  s.u_dq_V = Vec2(command.real(), command.imag());
  s.omega_el_rad_s = kOmega;
  s.u_dc_V = 48.0;
  for (int k = 1; k <= 2000; ++k) {
    s.t_start_ns = (k - 1) * 5'000'000LL;
    s.t_ns = k * 5'000'000LL;
    (void)est.step(s);
  }
  return est.psi_m_Wb() / kPsi_Wb - 1.0;
}

TEST(AveragedCycleSampling, ReportedCommandIsTurnedAndShortenedToTheMean) {
  // §11, "Reported command": with the delay extension and voltage_reported: command the estimate is the
  // sampled-means correction's (third order in ωT, < 0.03 %); the command taken for the mean is off by
  // percents at ωT = 0.35 (the q component alone: cos(ωT)/sinc(ωT/2) − 1 = −5.4 %).
  EXPECT_LT(std::abs(psi_m_bias_of_command(0.5, true)), 3e-4);
  EXPECT_GT(std::abs(psi_m_bias_of_command(0.5, false)), 0.01);
}

}  // namespace
}  // namespace rpem::core
