// Logs without d/q values (rotor_frame_rebuild.hpp): the rotor-frame values rebuilt from VESC's duty cycle and motor
// current against hand-derived numbers, and when they are rebuilt (columns absent, or 0 in every row) and when not.
#include "rpem/io/rotor_frame_rebuild.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "rpem/io/errors.hpp"

namespace rpem::io {
namespace {

constexpr double kNotRead = std::numeric_limits<double>::quiet_NaN();

core::MachineSi rebuild_machine() {
  core::MachineSi m;
  m.r_s_Ohm = 0.025;
  m.l_q_H = 20e-6;
  m.psi_m_Wb = 5e-3;
  return m;
}

/// A log of `n` windows at 1 000 rad/s whose d/q columns are absent (VESC Tool 1.17–1.19): duty 0.5 at 48 V
/// throughout, motor current 10 A.
struct RebuildLog {
  std::vector<core::AveragedSample> samples;
  AveragedLogRead read;
};
RebuildLog without_dq(std::size_t n) {
  RebuildLog l;
  l.read.layout.u_dc = l.read.layout.duty = l.read.layout.i_motor = true;
  for (std::size_t k = 0; k < n; ++k) {
    core::AveragedSample s;
    s.t_start_ns = static_cast<std::int64_t>(k) * 100'000'000;
    s.t_ns = s.t_start_ns + 100'000'000;
    s.omega_el_rad_s = 1000.0;
    s.u_dc_V = 48.0;
    s.u_dq_V = {kNotRead, kNotRead};
    s.i_dq_A = {kNotRead, kNotRead};
    l.samples.push_back(s);
    l.read.duty.push_back(0.5);
    l.read.duty_at_start.push_back(k == 0 ? kNotRead : 0.5);
    l.read.u_dc_at_start_V.push_back(k == 0 ? kNotRead : 48.0);
    l.read.i_motor_A.push_back(10.0);
  }
  return l;
}

// |u| = 0.5·48/√3 = 13.8564 V; i_q = +10 A; u_d = −ω·L_q·i_q = −0.2 V; u_q = √(13.8564² − 0.2²) = 13.85496 V.
TEST(RotorFrameRebuild, ADutyCycleAndAMotorCurrentGiveTheSteadyStateRotorFrame) {
  RebuildLog l = without_dq(2);
  const RotorFrameRebuild r = complete_rotor_frame(l.samples, l.read, rebuild_machine(), 0.0, "log.csv");
  EXPECT_TRUE(r.voltages && r.currents);
  EXPECT_EQ(r.short_magnitude, 0U);
  const double magnitude = 0.5 * 48.0 / std::numbers::sqrt3;
  for (const core::AveragedSample& s : l.samples) {
    EXPECT_DOUBLE_EQ(s.i_dq_A[0], 0.0);
    EXPECT_DOUBLE_EQ(s.i_dq_A[1], 10.0);
    EXPECT_NEAR(s.u_dq_V[0], -0.2, 1e-12);
    EXPECT_NEAR(s.u_dq_V[1], std::sqrt(magnitude * magnitude - 0.04), 1e-12);
    EXPECT_NEAR(s.u_dq_V[1], 13.85496, 1e-5);
  }
  EXPECT_NE(r.describe().find("i_d = 0, i_q = sign(duty)·i_motor; u_d, u_q rebuilt from |u| = |duty|·u_dc/√3"),
            std::string::npos)
      << r.describe();
  EXPECT_EQ(estimator_settings(MachineConfig{}, r).extensions.delay_s, 0.0);
}

// The firmware signs the duty by u_q and the motor current by u_q·i_q: generating in reverse (u_q < 0, i_q > 0) reads
// duty −0.5 and motor current −10 A, so i_q = sign(duty)·i_motor = +10 A and u_q < 0.
TEST(RotorFrameRebuild, TheSignsAreTheFirmwares) {
  RebuildLog l = without_dq(1);
  l.samples[0].omega_el_rad_s = -1000.0;
  l.read.duty[0] = -0.5;
  l.read.i_motor_A[0] = -10.0;
  (void)complete_rotor_frame(l.samples, l.read, rebuild_machine(), 0.0, "log.csv");
  EXPECT_DOUBLE_EQ(l.samples[0].i_dq_A[1], 10.0);
  EXPECT_NEAR(l.samples[0].u_dq_V[0], 0.2, 1e-12);  // −ω·L_q·i_q = +1000·20e-6·10
  EXPECT_NEAR(l.samples[0].u_dq_V[1], -13.85496, 1e-5);
}

// The duty is read at the window's end: where its start's read is known the window's magnitude is the mean of the
// two (0.4·48 and 0.6·50 V: 24.6 V over √3); a command held for T_c turning at ω averages to sinc(ω·T_c/2) of it.
TEST(RotorFrameRebuild, TheWindowsMagnitudeIsTheMeanOfItsTwoReadsAndAHeldCommandIsShortened) {
  RebuildLog l = without_dq(2);
  l.read.i_motor_A = {0.0, 0.0};
  l.read.duty = {0.4, 0.6};
  l.read.duty_at_start = {kNotRead, 0.4};
  l.samples[1].u_dc_V = 50.0;
  l.samples[0].u_dc_V = l.read.u_dc_at_start_V[1] = 48.0;
  const double t_c = 80e-6;
  (void)complete_rotor_frame(l.samples, l.read, rebuild_machine(), t_c, "log.csv");
  const double sinc = std::sin(0.5 * 1000.0 * t_c) / (0.5 * 1000.0 * t_c);
  EXPECT_NEAR(l.samples[0].u_dq_V[1], sinc * 0.4 * 48.0 / std::numbers::sqrt3, 1e-12);  // the first: its end alone
  EXPECT_NEAR(l.samples[1].u_dq_V[1], sinc * 0.5 * (0.4 * 48.0 + 0.6 * 50.0) / std::numbers::sqrt3, 1e-12);
  EXPECT_NEAR(sinc, 0.99973, 1e-5);
}

// Rows whose magnitude is below the model's |u_d| hold u_d to ±|u|, and are counted.
TEST(RotorFrameRebuild, AMagnitudeBelowTheModelsUdIsHeldAndCounted) {
  RebuildLog l = without_dq(1);
  l.read.duty[0] = 0.005;  // 0.139 V against u_d = −0.2 V
  const RotorFrameRebuild r = complete_rotor_frame(l.samples, l.read, rebuild_machine(), 0.0, "log.csv");
  EXPECT_EQ(r.short_magnitude, 1U);
  EXPECT_NEAR(l.samples[0].u_dq_V[0], -0.005 * 48.0 / std::numbers::sqrt3, 1e-12);
  EXPECT_DOUBLE_EQ(l.samples[0].u_dq_V[1], 0.0);
  EXPECT_NE(r.describe().find("1 samples with |u| below the model's |u_d|"), std::string::npos) << r.describe();
}

// Columns that hold 0 in every row (a logger that writes zeros for what it does not read) are rebuilt like absent
// ones; recorded columns are kept; zeros without a duty cycle are the error check_voltages_recorded gives.
TEST(RotorFrameRebuild, ZerosInEveryRowAreRebuiltRecordedValuesAreKept) {
  RebuildLog l = without_dq(2);
  l.read.layout.u_dq = l.read.layout.i_dq = true;
  for (core::AveragedSample& s : l.samples) s.u_dq_V = s.i_dq_A = {0.0, 0.0};
  EXPECT_TRUE(complete_rotor_frame(l.samples, l.read, rebuild_machine(), 0.0, "log.csv").voltages);
  EXPECT_NEAR(l.samples[1].u_dq_V[1], 13.85496, 1e-5);

  RebuildLog recorded = without_dq(2);
  recorded.read.layout.u_dq = recorded.read.layout.i_dq = true;
  for (core::AveragedSample& s : recorded.samples) s.u_dq_V = {-0.5, 12.0}, s.i_dq_A = {0.0, 9.0};
  const RotorFrameRebuild kept = complete_rotor_frame(recorded.samples, recorded.read, rebuild_machine(), 0.0, "log.csv");
  EXPECT_FALSE(kept.any());
  EXPECT_TRUE(kept.describe().empty());
  EXPECT_DOUBLE_EQ(recorded.samples[0].u_dq_V[1], 12.0);

  RebuildLog zeros = without_dq(2);
  zeros.read.layout.u_dq = true;
  zeros.read.duty = {0.0, 0.0};
  for (core::AveragedSample& s : zeros.samples) s.u_dq_V = {0.0, 0.0};
  EXPECT_THROW((void)complete_rotor_frame(zeros.samples, zeros.read, rebuild_machine(), 0.0, "zeros.csv"), DriveLogError);
}

TEST(RotorFrameRebuild, AWindowWithoutItsDcLinkIsAnErrorNamingIt) {
  RebuildLog l = without_dq(2);
  l.samples[1].u_dc_V = kNotRead;
  try {
    (void)complete_rotor_frame(l.samples, l.read, rebuild_machine(), 0.0, "log.csv");
    FAIL() << "no error";
  } catch (const DriveLogError& e) {
    EXPECT_NE(std::string(e.what()).find("log.csv: column u_dc: the window ending at t = 0.2 s has no DC-link voltage"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace rpem::io
