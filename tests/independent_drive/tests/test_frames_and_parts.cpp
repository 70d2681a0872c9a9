// The generator's parts against hand-derived answers: frames, modulation, delay line, MTPA, dead time,
// quantisation, profile and temperature tracks.
#include <gtest/gtest.h>

#include <cmath>

#include "case_fixtures.hpp"
#include "indep_drive/controller.hpp"
#include "indep_drive/frames.hpp"
#include "indep_drive/inverter.hpp"
#include "indep_drive/plant.hpp"
#include "indep_drive/profile.hpp"
#include "indep_drive/sensors.hpp"

namespace indep {
namespace {

TEST(IndepFrames, BalancedSetMapsToItsAmplitudeAndAngle) {
  // x_a = A·cos φ, x_b = A·cos(φ − 2π/3), x_c = A·cos(φ + 2π/3) is the vector A·e^{jφ}; at θ = φ − 0.3 its
  // rotor-frame value is A·e^{j0.3}.
  const double a = 3.7, phi = 1.1;
  const std::array<double, 3> abc{a * std::cos(phi), a * std::cos(phi - 2 * kPi / 3), a * std::cos(phi + 2 * kPi / 3)};
  const Vec2 ab = clarke(abc);
  EXPECT_NEAR(ab.x, a * std::cos(phi), 1e-12);
  EXPECT_NEAR(ab.y, a * std::sin(phi), 1e-12);
  const Vec2 dq = park(ab, phi - 0.3);
  EXPECT_NEAR(dq.x, a * std::cos(0.3), 1e-12);
  EXPECT_NEAR(dq.y, a * std::sin(0.3), 1e-12);
  const std::array<double, 3> back = inverse_clarke(inverse_park(dq, phi - 0.3));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(back[k], abc[k], 1e-12);
  // The common mode does not reach the vector.
  const Vec2 shifted = clarke({abc[0] + 5.0, abc[1] + 5.0, abc[2] + 5.0});
  EXPECT_NEAR(shifted.x, ab.x, 1e-12);
  EXPECT_NEAR(shifted.y, ab.y, 1e-12);
}

TEST(IndepModulation, LinearRangeIsHalfOrOneOverRootThreeOfTheDcLink) {
  const double u_dc = 100.0;
  for (Modulation m : {Modulation::sine, Modulation::third_harmonic, Modulation::space_vector}) {
    const double limit = linear_limit_V(u_dc, m);
    EXPECT_NEAR(limit, m == Modulation::sine ? 50.0 : 100.0 / std::sqrt(3.0), 1e-12);
    for (int k = 0; k < 360; ++k) {
      const double phi = k * kPi / 180.0;
      const std::array<double, 3> u = inverse_clarke({limit * std::cos(phi), limit * std::sin(phi)});
      const std::array<double, 3> d = duty_cycles(u, u_dc, m);
      // Inside the linear range the leg voltages differ exactly as the commands do (the zero sequence cancels).
      for (std::size_t x = 0; x < 3; ++x) {
        EXPECT_GE(d[x], -1e-12);
        EXPECT_LE(d[x], 1.0 + 1e-12);
        EXPECT_NEAR((d[x] - d[(x + 1) % 3]) * u_dc, u[x] - u[(x + 1) % 3], 1e-9) << modulation_name(m) << " at " << k;
      }
    }
  }
  // Sine modulation clips above u_dc/2: the a-leg saturates at an amplitude of 0.55·u_dc.
  const std::array<double, 3> over = inverse_clarke({55.0, 0.0});
  EXPECT_EQ(duty_cycles(over, u_dc, Modulation::sine)[0], 1.0);
}

TEST(IndepDelayLine, SplitsThePeriodBetweenTwoIssues) {
  DelayLine line(2.25);
  EXPECT_EQ(line.whole_periods(), 2);
  EXPECT_DOUBLE_EQ(line.fraction(), 0.25);
  for (int k = 0; k < 6; ++k) {
    line.push({double(k), 0.0, 0.0});
    // In period k: issue k−3 until 0.25·T_c, then issue k−2 (zero-voltage duties before the first issue).
    EXPECT_EQ(line.first()[0], k >= 3 ? double(k - 3) : 0.5);
    EXPECT_EQ(line.second()[0], k >= 2 ? double(k - 2) : 0.5);
  }
  EXPECT_THROW(DelayLine(4.0), std::invalid_argument);
}

TEST(IndepMtpa, GivesTheTorqueAtTheLeastCurrent) {
  const MachineParams m = testing::machine_case().machine.params;
  for (double torque : {5.0, 20.0, -12.0}) {
    const Vec2 i = mtpa_current(torque, m, 100.0);
    const double t = 1.5 * m.pole_pairs * (m.psi_m_Wb * i.y + (m.l_d_H - m.l_q_H) * i.x * i.y);
    EXPECT_NEAR(t, torque, 1e-9 * std::abs(torque));
    // No other current angle of the same magnitude gives more torque (brute force over 0.01° steps).
    const double magnitude = i.norm();
    double best = 0.0;
    for (int k = 0; k <= 18000; ++k) {
      const double beta = k * kPi / 18000.0 - kPi / 2;
      const Vec2 j{-magnitude * std::abs(std::sin(beta)), std::copysign(magnitude * std::cos(beta), torque)};
      best = std::max(best, std::abs(1.5 * m.pole_pairs * (m.psi_m_Wb * j.y + (m.l_d_H - m.l_q_H) * j.x * j.y)));
    }
    EXPECT_LE(best, std::abs(torque) * (1.0 + 1e-7));
  }
  // A surface machine (L_d = L_q) uses no d-axis current.
  MachineParams spm = m;
  spm.l_q_H = spm.l_d_H;
  EXPECT_EQ(mtpa_current(10.0, spm, 100.0).x, 0.0);
}

TEST(IndepDeadTime, IsTheTextbookAverageAwayFromZeroCurrentAndSmoothThrough) {
  const DeadTime d{2e-6 * 8000 * 560 + 1.0, 0.2};
  EXPECT_NEAR(d.error_V(5.0), -d.amplitude_V, 1e-9 * d.amplitude_V);  // tanh(25) = 1 − 4e−22
  EXPECT_NEAR(d.error_V(-5.0), d.amplitude_V, 1e-9 * d.amplitude_V);
  EXPECT_EQ(d.error_V(0.0), 0.0);
  EXPECT_NEAR(d.error_V(0.2), -d.amplitude_V * std::tanh(1.0), 1e-12);
}

TEST(IndepSensors, ErrorsComeBeforeNoiseAndQuantisation) {
  EXPECT_DOUBLE_EQ(quantise_bipolar(0.3, 10.0, 0), 0.3);
  const double lsb = 20.0 / 4096.0;
  EXPECT_NEAR(quantise_bipolar(0.3, 10.0, 12), std::round(0.3 / lsb) * lsb, 1e-15);
  EXPECT_DOUBLE_EQ(quantise_bipolar(25.0, 10.0, 12), 10.0);
  SensorSpec spec;
  spec.adc_bits = 12;
  spec.adc_full_scale_A = 10.0;
  spec.encoder_counts_per_rev = 1000;
  SensorErrors errors;
  errors.gain = {1.0, 1.05, 1.0};
  errors.offset_A = {0.2, 0.0, 0.0};
  errors.logged_minus_true_rad = 0.01;
  Sensors s(spec, errors, 4, 1);
  const std::array<double, 3> m = s.currents({1.0, 2.0, -3.0});
  EXPECT_NEAR(m[0], 1.2, lsb / 2);
  EXPECT_NEAR(m[1], 2.1, lsb / 2);
  EXPECT_NEAR(m[2], -3.0, lsb / 2);
  // Encoder: 1000 counts per mechanical turn, 4 pole pairs: an electrical step of 8π/1000.
  const double step_el = 4 * 2 * kPi / 1000;
  for (double theta : {0.3, 2.0, 5.9, 40.0}) {
    const double err = std::remainder(s.angle(theta) - (theta + 0.01), 2 * kPi);
    EXPECT_LE(std::abs(err), step_el / 2 + 1e-12) << theta;
  }
}

TEST(IndepProfile, InterpolatesAndSteps) {
  const OperatingProfile p({{0, 0, 0, 0}, {1, 100, 10, 0}, {1, 100, -5, 0}, {2, 300, -5, 1}});
  EXPECT_DOUBLE_EQ(p.at(0.5).speed_rpm, 50.0);
  EXPECT_DOUBLE_EQ(p.at(0.5).torque_Nm, 5.0);
  EXPECT_DOUBLE_EQ(p.at(1.0).torque_Nm, -5.0);  // at a step the later point holds
  EXPECT_DOUBLE_EQ(p.at(1.5).speed_rpm, 200.0);
  EXPECT_DOUBLE_EQ(p.at(1.5).i_d_inject_A, 0.5);
  EXPECT_DOUBLE_EQ(p.at(7.0).speed_rpm, 300.0);
  EXPECT_THROW(OperatingProfile({{0, 0, 0, 0}, {-1, 0, 0, 0}}), std::invalid_argument);
  const TemperatureTrack t{20.0, 80.0, 10.0};
  EXPECT_DOUBLE_EQ(t.at(0.0), 20.0);
  EXPECT_NEAR(t.at(10.0), 80.0 - 60.0 / std::exp(1.0), 1e-12);
}

TEST(IndepDefaultProfile, HasStandstillUnderLoadReversalAndVaryingSpeed) {
  const Case c = testing::machine_case();
  const OperatingProfile p = default_profile(c.machine, 20.0, 0.5, 0.8);
  EXPECT_EQ(p.at(1.0).speed_rpm, 0.0);
  EXPECT_GT(std::abs(p.at(1.0).torque_Nm), 0.3 * c.machine.torque_base_Nm());
  double lo = 0.0, hi = 0.0;
  for (double t = 0.0; t <= 20.0; t += 0.01) {
    lo = std::min(lo, p.at(t).speed_rpm);
    hi = std::max(hi, p.at(t).speed_rpm);
  }
  EXPECT_NEAR(hi, 500.0, 1e-9);
  EXPECT_NEAR(lo, -300.0, 1e-9);
}

}  // namespace
}  // namespace indep
