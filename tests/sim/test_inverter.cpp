// The inverter against the textbook: over a carrier period the mean leg voltage is d·u_dc, less
// sign(i)·t_dead·f_sw·u_dc from the dead time, less the conducting device's drop; the modulator's
// duties realise the command exactly in the linear range (up to u_dc/√3 with 3rd-harmonic injection).
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/frames.hpp"
#include "rpem/sim/inverter.hpp"

namespace rpem::sim {
namespace {

/// Mean phase-to-neutral αβ voltage over one full carrier period, integrated in plant steps of h.
core::Vec2 period_mean(const Inverter& inv, const Duties& d, const core::Vec3& i, double u_dc, double h) {
  core::Vec2 sum = core::Vec2::Zero();
  const int n = static_cast<int>(std::lround(inv.half_period_s() / h));
  for (bool rising : {true, false}) {
    for (int k = 0; k < n; ++k) sum += inv.mean_voltage(rising, k * h, h, d, i, u_dc);
  }
  return sum / (2.0 * n);
}

TEST(Inverter, SwitchingMeanEqualsDutyTimesDcLinkWithoutDeadTime) {
  InverterConfig c;
  const Inverter inv(c);
  Duties d;
  d.d = {0.73, 0.2, 0.5};
  const core::Vec2 mean = period_mean(inv, d, core::Vec3(1.0, -1.0, 0.5), 300.0, 1e-6);
  const core::Vec2 expected = core::clarke(300.0 * d.d);
  EXPECT_LT((mean - expected).norm(), 1e-9);
}

TEST(Inverter, DeadTimeProducesTheTextbookVoltageError) {
  InverterConfig c;
  c.dead_time_s = 3e-6;
  c.switching_frequency_Hz = 4000.0;
  const double u_dc = 220.0;
  const double v_err = c.dead_time_s * c.switching_frequency_Hz * u_dc;  // 2.64 V
  for (InverterModel model : {InverterModel::kSwitching, InverterModel::kAveraged}) {
    c.model = model;
    const Inverter inv(c);
    Duties d;
    d.d = {0.6, 0.45, 0.3};
    const core::Vec3 i(2.0, -0.5, -1.5);
    const double h = model == InverterModel::kSwitching ? 1e-6 : inv.half_period_s();
    const core::Vec2 mean = period_mean(inv, d, i, u_dc, h);
    const core::Vec3 legs(d.d[0] * u_dc - v_err, d.d[1] * u_dc + v_err, d.d[2] * u_dc + v_err);
    EXPECT_LT((mean - core::clarke(legs)).norm(), 1e-9) << static_cast<int>(model);
  }
}

TEST(Inverter, DeviceDropsFollowTheConductingDevice) {
  InverterConfig c;
  c.v_igbt_V = 1.2;
  c.v_diode_V = 0.8;
  const Inverter inv(c);
  Duties d;
  d.d = {0.25, 0.25, 0.25};
  // i > 0: high through the upper transistor (u_dc − 1.2), low through the lower diode (−0.8).
  const double h = 1e-6;
  const core::Vec2 mean = period_mean(inv, d, core::Vec3(1.0, -1.0, -1.0), 100.0, h);
  const core::Vec3 legs(0.25 * (100.0 - 1.2) + 0.75 * -0.8, 0.25 * (100.0 + 0.8) + 0.75 * 1.2,
                        0.25 * (100.0 + 0.8) + 0.75 * 1.2);
  EXPECT_LT((mean - core::clarke(legs)).norm(), 1e-9);
}

TEST(Modulator, ThirdHarmonicExtendsTheLinearRangeToDcOverSqrt3) {
  const double u_dc = 220.0;
  for (double phi = 0.0; phi < 2.0 * core::kPi; phi += 0.05) {
    const core::Vec2 u = (u_dc / core::kSqrt3 * 0.999) * core::Vec2(std::cos(phi), std::sin(phi));
    const Duties d = modulate(u, u_dc, true);
    for (int x = 0; x < 3; ++x) {
      EXPECT_GT(d.d[x], 0.0);
      EXPECT_LT(d.d[x], 1.0);
    }
    EXPECT_LT((core::clarke(u_dc * d.d) - u).norm(), 1e-9) << phi;
  }
  // Without injection the same amplitude saturates somewhere.
  bool saturated = false;
  for (double phi = 0.0; phi < 2.0 * core::kPi; phi += 0.05) {
    const Duties d = modulate((u_dc / core::kSqrt3 * 0.999) * core::Vec2(std::cos(phi), std::sin(phi)), u_dc, false);
    saturated = saturated || d.d.maxCoeff() >= 1.0 || d.d.minCoeff() <= 0.0;
  }
  EXPECT_TRUE(saturated);
}

}  // namespace
}  // namespace rpem::sim
