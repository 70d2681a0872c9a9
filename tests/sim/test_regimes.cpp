// The drive's regimes (sim/regime.hpp) against physics, and what the emulated VESC reports in them
// (sim/vesc_motor.hpp) against the firmware's rules written out here:
//   - open loop: the rotor follows the commanded angle at the load angle δ of the torque balance
//     (3/2)·p·ψm·I·sin δ = T_load + B·ω_m + J·dω_m/dt, and the reported frame is the commanded one:
//     u_d = −ω_c·L·I − ω·ψm·cos δ, u_q = R·I + ω·ψm·sin δ (the back EMF on u_d);
//   - bridge off: no current; the firmware reports i_d = i_q = 0 and the back EMF (0, ω·ψm) through its
//     first-order filter of 0.2 per cycle; the rotor coasts as J·dω_m/dt = −T_load − B·ω_m;
//   - zero-current coasting in closed loop decelerates by the same law;
//   - a speed step under the current limit accelerates at ((3/2)·p·ψm·I_max − T_load − B·ω_m)/J.
// The machine is the 6374 outrunner (config/vesc-6374-outrunner.yaml) with its ψm and R_s 20 % and 24 % off.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "rpem/core/frames.hpp"
#include "rpem/sim/drive_simulator.hpp"
#include "rpem/sim/vesc_motor.hpp"

namespace rpem::sim {
namespace {

constexpr double kPsiM = 0.0037, kRs = 0.031, kL = 20e-6;  // the plant (the configuration says 4.633 mWb, 25 mΩ)
constexpr double kJ = 0.004, kB = 1e-3, kLoad = 0.05;      // kg m², N m s, N m
constexpr int kP = 7;
constexpr double kPi = std::numbers::pi;

Scenario scenario(const std::string& initial, const std::string& regimes, double duration_s,
                  const std::string& control = "torque") {
  const std::string text =
      "name: regimes\nmachine: " + std::string(RPEM_TEST_SOURCE_DIR) +
      "/config/vesc-6374-outrunner.yaml\n"
      "duration_s: " +
      std::to_string(duration_s) +
      "\nwarmup_s: 0.02\nseed: 5\n"
      "sample_period_s: 80.0e-6\ninverter: {model: averaged, switching_frequency_Hz: 6250}\n"
      "plant: {step_s: 20.0e-6, mechanics: {mode: inertia, inertia_kgm2: 0.004, friction_Nms: 1.0e-3}}\n"
      "control: {current_bandwidth_Hz: 1000, mode: " +
      control +
      "}\n"
      "sensors: {current_noise_A: 0.15, current_lsb_A: 0.05}\n"
      "initial: {psi_m_Wb: 0.0037, r_s_Ohm: 0.031, u_dc_V: 48, load_torque_Nm: 0.05, " +
      initial +
      "}\n"
      "regimes:\n" +
      regimes;
  return parse_scenario(text, "regimes.yaml", "");
}

/// Mechanical speed after t of coasting from w0 under J·dω/dt = −T_load − B·ω.
double coast(double w0, double t) { return (w0 + kLoad / kB) * std::exp(-kB * t / kJ) - kLoad / kB; }

/// The load angle: from the rotor's d axis to the current, which the open loop holds on the commanded q axis.
double load_angle(const TruthRow& t) { return 0.5 * kPi + core::wrap_angle(t.theta_frame_rad - t.theta_el_rad); }

TEST(Regimes, OpenLoopRotorFollowsAtTheLoadAngleOfTheTorqueBalance) {
  // Lock 0.2 s, ramp to 400 rpm over 4 s, hold 3 s; 21 A.
  DriveSimulator sim(scenario(
      "speed_rpm: 0, torque_Nm: 0",
      "  - {t_s: 0.1, regime: open_loop, current_A: 21, speed_rpm: 400, lock_s: 0.2, ramp_s: 4, hold_s: 3}\n", 7.2));
  const double k = 1.5 * kP * kPsiM * 21.0;          // torque per sin δ [N m]
  const double w_target = 400.0 * 2.0 * kPi / 60.0;  // mechanical [rad/s]
  const double alpha = w_target / 4.0;               // during the ramp
  const double w_n = std::sqrt(kP * k / kJ);         // the rotor's natural frequency on the current [rad/s]
  io::DriveLogRow row;
  TruthRow t;
  double hold_sum = 0, hold_min = 1e9, hold_max = -1e9, hold_speed = 0, ramp_sum = 0, ramp_predicted = 0;
  int hold_n = 0, ramp_n = 0;
  while (sim.next(row, t)) {
    const double ts = 1e-9 * static_cast<double>(t.t_ns);
    if (t.regime != DriveRegime::kOpenLoop) continue;
    EXPECT_FALSE(t.angle_locked());
    const double delta = load_angle(t);
    if (ts > 4.4 && ts < 7.29) {  // the hold, less the first 0.1 s
      hold_sum += delta;
      hold_min = std::min(hold_min, delta);
      hold_max = std::max(hold_max, delta);
      hold_speed += t.omega_el_rad_s / kP;
      ++hold_n;
    } else if (ts > 1.3 && ts < 4.2) {  // the ramp, less its first second
      ramp_sum += delta;
      ramp_predicted += std::asin((kLoad + kB * t.omega_el_rad_s / kP + kJ * alpha) / k);
      ++ramp_n;
    }
  }
  ASSERT_GT(hold_n, 30000);
  ASSERT_GT(ramp_n, 30000);
  // The rotor oscillates about the equilibrium (nothing but B damps it): a sinusoid's mean over a window of
  // N periods is off its centre by at most its amplitude/(π·N).
  const double periods = 2.89 * w_n / (2.0 * kPi);
  const double tolerance = 0.5 * (hold_max - hold_min) / (kPi * periods) + 2e-3;
  const double expected = std::asin((kLoad + kB * w_target) / k);
  EXPECT_NEAR(hold_sum / hold_n, expected, tolerance) << "amplitude " << 0.5 * (hold_max - hold_min);
  EXPECT_NEAR(hold_speed / hold_n, w_target, 1e-3 * w_target);  // synchronous: no slip on average
  EXPECT_NEAR(ramp_sum / ramp_n, ramp_predicted / ramp_n, 0.01);
  EXPECT_GT(expected, 0.1);  // a load angle worth measuring (6.5°)
}

TEST(Regimes, OpenLoopReportsTheCommandedFrameWithTheBackEmfOnTheDAxis) {
  VescMotor motor(
      scenario("speed_rpm: 0, torque_Nm: 0",
               "  - {t_s: 0.1, regime: open_loop, current_A: 21, speed_rpm: 400, lock_s: 0.2, ramp_s: 2, hold_s: 3}\n", 5.3),
      {});
  const double w_c = 400.0 * 2.0 * kPi / 60.0 * kP;  // the commanded speed in the hold [rad/s, electrical]
  ASSERT_TRUE(motor.advance_to(2'500'000'000));
  (void)motor.read_values();
  int windows = 0;
  for (; windows < 25; ++windows) {  // 25 reads of 1250 cycles (100 ms) through the hold
    double d = 0, q = 0, speed = 0;
    constexpr int kCycles = 1250;
    for (int c = 0; c < kCycles; ++c) {
      const TruthRow t = motor.truth();  // the start of the cycle this step completes
      ASSERT_TRUE(motor.step());
      ASSERT_EQ(t.regime, DriveRegime::kOpenLoop);
      const double delta = load_angle(t);
      d += -w_c * kL * 21.0 - t.omega_el_rad_s * kPsiM * std::cos(delta);
      q += kRs * 21.0 + t.omega_el_rad_s * kPsiM * std::sin(delta);
      speed += t.omega_el_rad_s;
    }
    ASSERT_EQ(motor.cycles_since_read(), kCycles);
    const can::vesc::Values v = motor.read_values();
    // The frame's speed is the commanded one, which the PLL follows; the current is held on its q axis.
    // The rotor hunts about its load angle at ω_n ≈ 38 rad/s (nothing damps it), which moves the back EMF in
    // the commanded frame by ΔE ≈ ω·ψm·Δδ ≈ 0.1 V; the current PI (k_i = 2π·1 kHz·R) then errs by
    // ω_n·ΔE/k_i ≈ 0.025 A, and the 0.15 A sensor noise by 3σ/√1250 = 0.013 A over a read.
    // The PLL's speed settles on it after the ramp (400 rpm in 2 s, ended at 2.3 s) with its slow pole p₁:
    // within a·τ·p₂/(p₂ − p₁)·e^{−p₁·(t − 2.3 s)} (docs/derivations.md §13, "Speed at the read").
    const double kp = can::vesc::kDefaultPllKp, ki = can::vesc::kDefaultPllKi, root = std::sqrt(kp * kp - 4.0 * ki);
    const double p1 = 0.5 * (kp - root), p2 = 0.5 * (kp + root);
    const double t_read = 2.5 + 0.1 * (windows + 1);
    const double settle_erpm = (400.0 * kP / 2.0) * (kp / ki) * p2 / (p2 - p1) * std::exp(-p1 * (t_read - 2.3));
    EXPECT_NEAR(v.erpm, w_c * 60.0 / (2.0 * kPi), settle_erpm + 1e-6) << "window " << windows;
    EXPECT_NEAR(v.i_q_A, 21.0, 0.05);
    EXPECT_NEAR(v.i_d_A, 0.0, 0.05);
    // u from the rotor's state: 10 mV covers the PI's response to the 0.15 A sensor noise and the current's
    // tracking error (R·0.02 A, ω·L·0.02 A are below 1 mV).
    EXPECT_NEAR(v.v_d_V, d / kCycles, 0.01) << "window " << windows;
    EXPECT_NEAR(v.v_q_V, q / kCycles, 0.01) << "window " << windows;
    EXPECT_LT(v.v_d_V, -0.8 * w_c * kPsiM);  // the back EMF is on −d: the rotor's q axis is the frame's −d
  }
  EXPECT_EQ(windows, 25);
}

/// Steps through a bridge-off interval, checking every cycle the firmware sums against its rules; returns
/// the number of off cycles. `zero`: the variant that reports v_d = v_q = 0.
int check_bridge_off(VescMotor& motor, bool zero) {
  int off = 0;
  double w0 = 0, t0 = 0, w_last = 0, t_last = 0;
  for (;;) {
    const core::Vec2 previous_u = motor.last_cycle().u_dq_V;
    const TruthRow t = motor.truth();
    if (!motor.step()) break;
    if (t.regime != DriveRegime::kBridgeOff) {
      if (off > 0) break;
      continue;
    }
    EXPECT_FALSE(t.modulating());
    EXPECT_TRUE(t.angle_locked());
    const ControlCycle& c = motor.last_cycle();
    EXPECT_EQ(c.i_dq_A[0], 0.0);  // "The current is 0 when the motor is undriven"
    EXPECT_EQ(c.i_dq_A[1], 0.0);
    if (off > 0) {  // the plant's current returned to the DC link during the first off period
      EXPECT_EQ(t.i_dq_A.norm(), 0.0);
      EXPECT_EQ(t.torque_Nm, 0.0);
    }
    if (zero) {
      EXPECT_EQ(c.u_dq_V.norm(), 0.0);
    } else {
      // UTILS_LP_FAST(vd, vd_tmp, 0.2) of the back EMF at zero current, (0, ω·ψm) in the rotor frame.
      const core::Vec2 e(0.0, t.omega_el_rad_s * kPsiM);
      const core::Vec2 expected = previous_u + 0.2 * (e - previous_u);
      EXPECT_NEAR(c.u_dq_V[0], expected[0], 1e-12);
      EXPECT_NEAR(c.u_dq_V[1], expected[1], 1e-12);
    }
    if (off == 0) {
      w0 = t.omega_el_rad_s / kP;
      t0 = 1e-9 * static_cast<double>(t.t_ns);
    }
    w_last = t.omega_el_rad_s / kP;
    t_last = 1e-9 * static_cast<double>(t.t_ns);
    ++off;
  }
  // The rotor coasted on its inertia against load and friction (explicit Euler in 20 µs steps: 1e-5).
  EXPECT_NEAR(w_last, coast(w0, t_last - t0), 1e-5 * w0);
  EXPECT_LT(w_last, 0.9 * w0);
  return off;
}

TEST(Regimes, BridgeOffFreewheelsAndReportsWhatTheFirmwareReports) {
  for (const bool zero : {false, true}) {
    SCOPED_TRACE(zero ? "report: zero" : "report: back_emf");
    const std::string off =
        zero ? "  - {t_s: 0.3, regime: bridge_off, report: zero}\n" : "  - {t_s: 0.3, regime: bridge_off}\n";
    VescMotor motor(scenario("speed_rpm: 2000, torque_Nm: 0", off + "  - {t_s: 2.3, regime: closed_loop}\n", 2.6), {});
    // A read wholly inside the interval: no current at all, and the back EMF (or nothing).
    ASSERT_TRUE(motor.advance_to(1'000'000'000));
    (void)motor.read_values();
    double w = 0;
    for (int c = 0; c < 1250; ++c) {
      const TruthRow t = motor.truth();
      ASSERT_TRUE(motor.step());
      w += t.omega_el_rad_s;
    }
    const double dw_dt = (motor.truth().omega_el_rad_s - w / 1250) / 0.05;  // electrical, over the read's second half
    const can::vesc::Values v = motor.read_values();
    EXPECT_EQ(v.i_d_A, 0.0);
    EXPECT_EQ(v.i_q_A, 0.0);
    EXPECT_EQ(v.current_motor_A, 0.0);
    EXPECT_EQ(v.current_in_A, 0.0);
    EXPECT_NEAR(v.v_d_V, 0.0, 1e-9);
    // The filter (a first-order lag of (1 − 0.2)/0.2 = 4 cycles) trails the falling back EMF by
    // 4·T·|dω/dt|·ψm = 0.4 mV here.
    const double lag = 4.0 * 80e-6 * std::abs(dw_dt) * kPsiM;
    EXPECT_NEAR(v.v_q_V, zero ? 0.0 : w / 1250 * kPsiM + lag, zero ? 0.0 : 0.05 * lag + 1e-7);
    EXPECT_GT(check_bridge_off(motor, zero), 10000);
  }
}

TEST(Regimes, ZeroCurrentCoastingDeceleratesFromInertiaAndFriction) {
  VescMotor motor(scenario("speed_rpm: 2000, torque_Nm: 0", "  - {t_s: 0, regime: closed_loop}\n", 3.0), {});
  ASSERT_TRUE(motor.advance_to(100'000'000));
  const double t0 = 1e-9 * static_cast<double>(motor.truth().t_ns), w0 = motor.truth().omega_el_rad_s / kP;
  (void)motor.read_values();
  double psi_omega = 0;
  int n = 0;
  for (;;) {
    const TruthRow t = motor.truth();
    if (!motor.step()) break;
    psi_omega += t.omega_el_rad_s * kPsiM;
    ++n;
  }
  const can::vesc::Values v = motor.read_values();
  const double t1 = 1e-9 * static_cast<double>(motor.truth().t_ns), w1 = motor.truth().omega_el_rad_s / kP;
  // The current controller holds i ≈ 0: its mean torque is (3/2)·p·ψm·mean(i_q), which the read bounds.
  EXPECT_NEAR(v.i_q_A, 0.0, 0.01);
  EXPECT_NEAR(v.i_d_A, 0.0, 0.01);
  // The bridge modulates the back EMF: ū = R·ī + ω·L·J·ī + (0, ω·ψm) for the cycles' mean current ī, which
  // the firmware's samples (at each cycle's start, where the PI holds them at 0) miss by the ripple of the
  // voltage turning ω·T_c in the rotor frame: ī = i_sample + ω·T_c²/(12·L)·J·ū (docs/derivations.md §11,
  // "Sampled means", a = 0): −0.16 A on d at this speed. What remains: the plant's Heun steps
  // ((ω·h)²/12·|ū|, 0.3 mV) and third-order terms.
  const double c = (psi_omega / n / kPsiM) * 80e-6 * 80e-6 / (12.0 * kL);
  const core::Vec2 i_mean(v.i_d_A - c * v.v_q_V, v.i_q_A + c * v.v_d_V);
  const double omega = psi_omega / n / kPsiM;
  EXPECT_NEAR(v.v_q_V, kRs * i_mean[1] + omega * kL * i_mean[0] + psi_omega / n, 1.5e-3);
  EXPECT_NEAR(v.v_d_V, kRs * i_mean[0] - omega * kL * i_mean[1], 1.5e-3);
  // ω(t) against the law; a residual mean current of 0.01 A would move it by p·1.5·ψm·0.01·(t1 − t0)/J.
  const double bound = 1.5 * kP * kPsiM * 0.01 * (t1 - t0) / kJ;
  EXPECT_NEAR(w1, coast(w0, t1 - t0), bound);
  EXPECT_LT(w1, 0.85 * w0);
}

TEST(Regimes, ASpeedStepUnderTheCurrentLimitAcceleratesHardWithinOneRead) {
  // The speed reference steps from 0 to 3000 rpm at t = 0.1 s.
  Scenario s = scenario("speed_rpm: 0, torque_Nm: 0", "  - {t_s: 0, regime: closed_loop}\n", 0.6, "speed");
  s.signal(Quantity::kSpeed).add({0.1, EventKind::kStep, 3000.0, 0.0});
  VescMotor motor(std::move(s), {});
  const double i_max = std::sqrt(2.0) * 40.0;      // control.max_current_A's default: √2·I_n
  const double torque = 1.5 * kP * kPsiM * i_max;  // the true torque at the limit (ψm below nominal)
  const double w_inf = (torque - kLoad) / kB;
  ASSERT_TRUE(motor.advance_to(200'000'000));
  const double t0 = 1e-9 * static_cast<double>(motor.truth().t_ns), w0 = motor.truth().omega_el_rad_s / kP;
  (void)motor.read_values();
  ASSERT_TRUE(motor.advance_to(300'000'000));  // one read of 100 ms
  const can::vesc::Values v = motor.read_values();
  const double t1 = 1e-9 * static_cast<double>(motor.truth().t_ns), w1 = motor.truth().omega_el_rad_s / kP;
  const double expected = (w0 - w_inf) * std::exp(-kB * (t1 - t0) / kJ) + w_inf;
  EXPECT_NEAR(w1, expected, 2e-3 * (expected - w0));
  EXPECT_GT(w1 - w0, 50.0);           // rad/s mechanical within one read: 40 % of the speed
  EXPECT_NEAR(v.i_q_A, i_max, 0.05);  // the window's mean current: at the limit throughout
  // The end's speed as the firmware's PLL reports it: behind the rotor by its ramp response since the step at
  // 0.1 s, a·(τ − p₂/(p₁(p₂ − p₁))·e^{−p₁·t'}), τ = k_p/k_i (docs/derivations.md §13, "Speed at the read"), with
  // a the read's mean acceleration (the rotor accelerates nearly evenly here: J/B ≫ the read).
  const double kp = can::vesc::kDefaultPllKp, ki = can::vesc::kDefaultPllKi, root = std::sqrt(kp * kp - 4.0 * ki);
  const double p1 = 0.5 * (kp - root), p2 = 0.5 * (kp + root);
  const double a = (w1 - w0) * kP / (t1 - t0);
  const double lag = a * (kp / ki - p2 / (p1 * (p2 - p1)) * std::exp(-p1 * (t1 - 0.1)));
  EXPECT_NEAR(v.erpm * 2.0 * kPi / 60.0, w1 * kP - lag, 0.05 * lag);
}

TEST(Regimes, AnOpenLoopMeasurementReleasesTheBridgeAfterItsHold) {
  DriveSimulator sim(scenario("speed_rpm: 0, torque_Nm: 0",
                              "  - {t_s: 0.1, regime: open_loop, current_A: 20, speed_rpm: 300, ramp_s: 0.5, hold_s: 0.2, "
                              "then: bridge_off}\n",
                              1.2));
  io::DriveLogRow row;
  TruthRow t;
  std::vector<DriveRegime> seen;
  while (sim.next(row, t)) {
    if (seen.empty() || seen.back() != t.regime) seen.push_back(t.regime);
    const double ts = 1e-9 * static_cast<double>(t.t_ns);
    if (ts >= 0.1 && ts < 0.8 - 1e-9) {
      EXPECT_EQ(t.regime, DriveRegime::kOpenLoop) << ts;
    }
    if (ts >= 0.8 + 1e-9) {
      EXPECT_EQ(t.regime, DriveRegime::kBridgeOff) << ts;
    }
    if (t.regime == DriveRegime::kBridgeOff) {
      EXPECT_EQ(row.sample.u_V.norm(), 0.0);  // the drive commands nothing
    }
  }
  EXPECT_EQ(seen, (std::vector<DriveRegime>{DriveRegime::kClosedLoop, DriveRegime::kOpenLoop, DriveRegime::kBridgeOff}));
}

}  // namespace
}  // namespace rpem::sim
