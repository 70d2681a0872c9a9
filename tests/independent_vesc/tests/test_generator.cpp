// The generator as a whole, against the physics and the firmware's sources (README "Validation"):
//  - steady state at a locked point: the terminal voltage in the true rotor frame is R·i + jω(L·i + ψm), and
//    what VESC reports is that voltage as the firmware's timing turns it;
//  - open loop at constant speed: the rotor lags the commanded current by its load angle and the back EMF
//    appears on the reported u_d;
//  - each row holds the means of the firmware's per-cycle values since the previous read;
//  - the bridge off: i = 0 exactly, the back EMF on u_q (or zeros); the open-loop start-up's sequence;
//  - one seed, one file.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "fixtures.hpp"
#include "indep_vesc/observer.hpp"

namespace indep::vesc {
namespace {

using testing::outrunner_case;
using testing::rows_between;
using testing::segment;
using cplx = std::complex<double>;

/// R·i + jω(L·i + ψ) with L_d = L_q (the outrunner is not salient), i the current's mean over time.
cplx steady_voltage(const RowTruth& t, double l_H) {
  const cplx i{t.i_d_avg_A, t.i_q_avg_A};
  return t.r_s_Ohm * i + cplx{0.0, t.omega_el_mean_rad_s} * (l_H * i + t.psi_m_Wb);
}

/// What VESC reports for a terminal voltage u (true rotor frame, mean over the application window): the command
/// computed in the frame of the sample (ε off the rotor's d axis) is applied from half a period after the sample
/// for one period (center-aligned PWM, preloaded compare registers taken at each update event: mcpwm_foc.c's
/// timer set-up), i.e. centered one period later, as a vector fixed in the stator frame. Its mean in the rotor
/// frame is the command turned by ε − ωT and shortened by sinc(ωT/2).
cplx reported_for(cplx u, double omega, double eps, double period) {
  const double half = 0.5 * omega * period;
  const double sinc = std::fabs(half) < 1e-9 ? 1.0 : std::sin(half) / half;
  return u * std::polar(1.0, omega * period - eps) / sinc;
}

// ψm +15 %, R_s −20 %; 5 A from standstill against the bearings and drag: the shaft settles near 34 000 ERPM
// (ω_e ≈ 3 600 rad/s) within 3 s (τ = J/(2kω) ≈ 0.5 s).
TEST(IndepVescGenerator, SteadyStateAtALockedPointMeetsTheDqEquations) {
  Case cs = outrunner_case(10.0);
  cs.scenario = {segment(SegmentKind::current, 8.0, 5.0), segment(SegmentKind::off, 2.0)};
  const Result r = generate(cs);
  const double l = r.true_at_reference.l_d_H, period = r.control_period_s;
  const auto rows = rows_between(r, 5.0, 8.0);
  ASSERT_GT(rows.size(), 25u);
  for (const LogRow* row : rows) {
    const RowTruth& t = row->truth;
    ASSERT_EQ(t.bridge, "modulating");
    ASSERT_TRUE(t.angle_locked) << t.t_read_s;
    const cplx u_true{t.u_d_mean_V, t.u_q_mean_V};
    const cplx model = steady_voltage(t, l);
    // The plant: exact up to the window's slow deceleration (L·di/dt) and the samples' timing: 2 mV of 19 V.
    EXPECT_LT(std::abs(u_true - model), 2e-3) << "t " << t.t_read_s << " u " << u_true << " model " << model;
    // What VESC reports: the same voltage through the firmware's timing, within the dead-time compensation's
    // timing error (≈ (4/π)·ΔV·ωT ≈ 30 mV) and the wire's 1 mV.
    const cplx v_rep{row->context.values.vd, row->context.values.vq};
    const cplx expected = reported_for(u_true, t.omega_el_mean_rad_s, t.frame_error_mean_rad, period);
    EXPECT_LT(std::abs(v_rep - expected), 0.05) << "t " << t.t_read_s << " reported " << v_rep << " expected " << expected;
    // ... and is not the voltage in the rotor frame: u_d differs by about ωT·u_q (0.28 rad at this speed).
    EXPECT_GT(std::fabs(v_rep.real() - u_true.real()), 0.2 * t.omega_el_mean_rad_s * period * std::fabs(u_true.imag()));
    // The current is reported in the frame of the samples, ε off the true one.
    const cplx i_rep{row->context.values.id, row->context.values.iq};
    const cplx i_expected = cplx{t.i_d_mean_A, t.i_q_mean_A} * std::polar(1.0, -t.frame_error_mean_rad);
    EXPECT_LT(std::abs(i_rep - i_expected), 0.05) << "t " << t.t_read_s;
  }
}

// VESC Tool's flux measurement at 20 A against the bench's drag and bearings plus 0.05 Nm: at 12 000 ERPM the
// rotor's d axis lags the commanded current by γ = asin(T/(1.5·p·ψm·|i|)) (L_d = L_q), so the commanded frame is
// π/2 − γ behind the rotor's and the back EMF ω·ψm lands on u_d:
// u_dq,commanded ≈ (−ωψm·cos γ − ωL|i|, R|i| + ωψm·sin γ).
TEST(IndepVescGenerator, OpenLoopRotorLagsByItsLoadAngle) {
  Case cs = outrunner_case(14.0);
  Segment flux = segment(SegmentKind::flux_measurement, 30.0, 20.0);
  flux.friction_Nm = 0.05;
  cs.scenario = {segment(SegmentKind::off, 0.05), flux, segment(SegmentKind::off, 3.0)};
  const Result r = generate(cs);
  const SegmentSpan& span = r.spans.at(1);
  ASSERT_EQ(span.segment.kind, SegmentKind::flux_measurement);
  const double p = r.true_at_reference.pole_pairs, l = r.true_at_reference.l_d_H, period = r.control_period_s;
  PlantParams load = r.plant;
  load.coulomb_Nm += 0.05;
  const Plant shaft(load);
  int checked = 0;
  double gamma_sum = 0.0, expected_sum = 0.0;
  // Constant speed from the end of the ramp: 1 s settling, 1 s averaging, 0.5 s configuring, ≤ 0.2 s undriven.
  for (const LogRow* row : rows_between(r, span.t_end_s - 2.2, span.t_end_s - 0.9)) {
    const RowTruth& t = row->truth;
    ASSERT_EQ(t.angle, "open_loop");
    ASSERT_NEAR(t.omega_el_mean_rad_s, 12000.0 * 2.0 * kPi / 60.0, 3.0) << "constant 12 000 ERPM, the shaft swinging";
    ++checked;
    const double i_mag = std::hypot(t.i_d_mean_A, t.i_q_mean_A);
    const double gamma = std::atan2(t.i_q_mean_A, t.i_d_mean_A);
    gamma_sum += gamma;
    expected_sum += std::asin(shaft.load_torque_Nm(t.omega_el_mean_rad_s / p) / (1.5 * p * t.psi_m_Wb * i_mag));
    // The current is reported in the commanded frame, ε = θ_commanded − θ_rotor off the rotor's: its angle
    // there plus ε is its angle from the rotor's d axis, the load angle (per sample exactly; the window's means
    // of angles and of vectors differ by the swing within the window, < 0.01 rad).
    const double reported_angle = std::atan2(row->context.values.iq, row->context.values.id);
    EXPECT_NEAR(reported_angle + t.frame_error_mean_rad, gamma, 0.01) << t.t_read_s;
    const cplx u_true{t.u_d_mean_V, t.u_q_mean_V};
    EXPECT_LT(std::abs(u_true - steady_voltage(t, l)), 5e-3) << t.t_read_s;
    const cplx v_rep{row->context.values.vd, row->context.values.vq};
    EXPECT_LT(std::abs(v_rep - reported_for(u_true, t.omega_el_mean_rad_s, t.frame_error_mean_rad, period)), 0.05);
    // In the commanded frame: the current on q (the controller follows the shaft's swing within 0.3 A),
    // the back EMF on u_d.
    EXPECT_NEAR(row->context.values.iq, i_mag, 0.3);
    EXPECT_NEAR(row->context.values.id, 0.0, 0.3);
    EXPECT_LT(row->context.values.vd, -0.9 * t.omega_el_mean_rad_s * t.psi_m_Wb);
  }
  ASSERT_GT(checked, 8);
  // The shaft swings about its load angle by ±0.02 rad at ~10 Hz; over the 1.3 s the mean sits on it.
  EXPECT_NEAR(gamma_sum / checked, expected_sum / checked, 3e-3);
  // The VESC keeps the undriven flux linkage (v_q/ω while it coasts), close to the true one.
  ASSERT_TRUE(r.vesc_measured_flux_Wb.has_value());
  EXPECT_NEAR(*r.vesc_measured_flux_Wb / r.true_at_reference.psi_m_Wb, 1.0, 0.05);
}

// Each row: the means since the previous read of what the firmware adds every cycle (mcpwm_foc_get_id/iq/vd/vq),
// through the wire's truncation (0.01 A, 1 mV) and single-precision sums.
TEST(IndepVescGenerator, RowsHoldTheMeansSinceThePreviousRead) {
  Case cs = outrunner_case(4.0);
  cs.keep_cycle_trace = true;
  cs.poller.loss_probability = 0.2;   // lost replies: windows that start at a read no row shows
  cs.poller.stall_probability = 0.0;  // rows in the order of their reads
  cs.scenario = {segment(SegmentKind::off, 0.2), segment(SegmentKind::current, 0.6, 20.0),
                 segment(SegmentKind::current, 0.1, 60.0), segment(SegmentKind::current, 2.0, 5.0),
                 segment(SegmentKind::off, 1.1)};
  const Result r = generate(cs);
  ASSERT_EQ(r.cycles.size(), 50000u);
  ASSERT_GT(r.lost_replies, 0);
  std::size_t k = 0;
  double previous_read = -1.0;
  for (const LogRow& row : r.rows) {
    const RowTruth& t = row.truth;
    ASSERT_GE(t.t_window_start_s, previous_read) << "windows are disjoint and in order";
    previous_read = t.t_read_s;
    // A read at t takes the sums of every interrupt at or before t.
    while (k < r.cycles.size() && t.t_window_start_s > 0.0 && r.cycles[k].t_s <= t.t_window_start_s) ++k;
    double id = 0, iq = 0, vd = 0, vq = 0;
    int n = 0;
    for (; k < r.cycles.size() && r.cycles[k].t_s <= t.t_read_s; ++k, ++n) {
      id += r.cycles[k].i_dq_reported_A.x;
      iq += r.cycles[k].i_dq_reported_A.y;
      vd += r.cycles[k].v_dq_reported_V.x;
      vq += r.cycles[k].v_dq_reported_V.y;
    }
    ASSERT_EQ(n, t.cycles) << t.t_read_s;
    ASSERT_GT(n, 0);
    const McValues& v = row.context.values;
    // Truncation toward zero loses up to one quantum; the float sums add ~n·2⁻²⁴ of the mean's size.
    auto close = [&](double reported, double mean, double quantum) {
      return std::fabs(reported - mean) <= quantum + 1e-4 * std::fabs(mean) + 1e-9;
    };
    EXPECT_TRUE(close(v.id, id / n, 0.01)) << t.t_read_s << ": " << v.id << " vs " << id / n;
    EXPECT_TRUE(close(v.iq, iq / n, 0.01)) << t.t_read_s << ": " << v.iq << " vs " << iq / n;
    EXPECT_TRUE(close(v.vd, vd / n, 0.001)) << t.t_read_s << ": " << v.vd << " vs " << vd / n;
    EXPECT_TRUE(close(v.vq, vq / n, 0.001)) << t.t_read_s << ": " << v.vq << " vs " << vq / n;
  }
}

TEST(IndepVescGenerator, BridgeOffReportsNoCurrentAndTheBackEmfOrZeros) {
  Case cs = outrunner_case(8.0);
  cs.scenario = {segment(SegmentKind::current, 5.0, 5.0), segment(SegmentKind::off, 3.0)};
  for (const OffVoltage mode : {OffVoltage::measured, OffVoltage::zero}) {
    cs.firmware.off_voltage = mode;
    const Result r = generate(cs);
    int checked = 0;
    for (const LogRow* row : rows_between(r, 5.2, 8.0)) {
      const RowTruth& t = row->truth;
      ASSERT_EQ(t.bridge, "bridge_off");
      ++checked;
      EXPECT_EQ(row->context.values.id, 0.0);  // mcpwm_foc_adc_int_handler zeroes them while undriven
      EXPECT_EQ(row->context.values.iq, 0.0);
      if (mode == OffVoltage::zero) {
        EXPECT_EQ(row->context.values.vq, 0.0);
        EXPECT_EQ(row->context.values.vd, 0.0);
      } else {
        // The measured back EMF jωψm in the frame of the observer's angle, which the firmware sets
        // foc_observer_offset (−1) periods back: ε ≈ −ωT behind the rotor's d axis (0.1–0.3 rad here).
        const cplx expected = cplx{0.0, t.omega_el_mean_rad_s * t.psi_m_Wb} * std::polar(1.0, -t.frame_error_mean_rad);
        EXPECT_NEAR(row->context.values.vq, expected.imag(), 0.01 * t.psi_m_term_V + 0.01) << t.t_read_s;
        EXPECT_NEAR(row->context.values.vd, expected.real(), 0.01 * t.psi_m_term_V + 0.01) << t.t_read_s;
        EXPECT_LT(t.frame_error_mean_rad, 0.0);
      }
    }
    EXPECT_GT(checked, 20);
  }
}

// The sensorless start against a load: after sl_openloop_hyst (0.1 s) below the open-loop speed the commanded
// angle jumps 60° ahead of the observer's and advances in 1 ms steps (the foc timer thread) for
// t_ramp + t_const = 0.15 s.
TEST(IndepVescGenerator, OpenLoopStartUpFollowsTheFirmwaresSequence) {
  Case cs = outrunner_case(1.5);
  cs.keep_cycle_trace = true;
  Segment start = segment(SegmentKind::current, 1.3, 20.0);
  start.friction_Nm = 0.9;
  cs.scenario = {segment(SegmentKind::off, 0.2), start};
  const Result r = generate(cs);
  const auto& cy = r.cycles;
  std::size_t first_on = 0;
  while (first_on < cy.size() && !cy[first_on].modulating) ++first_on;
  std::size_t a = first_on;
  while (a < cy.size() && cy[a].source != AngleSource::startup) ++a;
  ASSERT_LT(a, cy.size()) << "no open-loop start-up";
  EXPECT_GE(cy[a].t_s - cy[first_on].t_s, 0.1 - 2e-3);
  std::size_t b = a;
  while (b < cy.size() && cy[b].source == AngleSource::startup) ++b;
  EXPECT_NEAR(cy[b].t_s - cy[a].t_s, 0.15, 2e-3);
  EXPECT_NEAR(wrap_pi(cy[a].phase_rad - cy[a - 1].phase_rad), kPi / 3.0, 0.05) << "the 60° jump ahead";
  int steps = 0;
  for (std::size_t k = a + 1; k < b; ++k) {
    if (cy[k].phase_rad != cy[k - 1].phase_rad) {
      ++steps;
      EXPECT_GE(wrap_pi(cy[k].phase_rad - cy[k - 1].phase_rad), 0.0) << "forward only";
    }
  }
  EXPECT_NEAR(steps, 150, 3) << "one step per millisecond";
}

TEST(IndepVescGenerator, OneSeedOneFile) {
  Case cs = outrunner_case(3.0);
  const std::string a = vesc_tool_csv(generate(cs)), b = vesc_tool_csv(generate(cs));
  EXPECT_EQ(a, b);
  cs.seed = 2;
  EXPECT_NE(a, vesc_tool_csv(generate(cs)));
}

}  // namespace
}  // namespace indep::vesc
