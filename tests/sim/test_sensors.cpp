#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/types.hpp"
#include "rpem/sim/sensors.hpp"

namespace rpem::sim {
namespace {

TEST(Sensors, CurrentGainOffsetAndQuantisation) {
  SensorConfig c;
  c.current_offset_A = {0.1, 0.0, -0.2};
  c.current_gain_error = {0.0, 0.02, 0.0};
  c.current_lsb_A = 0.01;
  Sensors s(c, 3, 125e-6, 1);
  const core::Vec3 i = s.currents({1.0, 2.0, -3.0});
  EXPECT_NEAR(i[0], 1.1, 1e-12);
  EXPECT_NEAR(i[1], 2.04, 1e-12);
  EXPECT_NEAR(i[2], -3.2, 1e-12);
}

TEST(Sensors, EncoderResolutionOffsetAndSpeed) {
  SensorConfig c;
  c.encoder_counts = 1024;
  c.theta_offset_rad = 0.1;
  c.speed_window = 8;
  const int p = 3;
  Sensors s(c, p, 125e-6, 1);
  const double omega_el = 150.0;
  double theta = 0.0;
  double measured = 0.0;
  for (int k = 0; k < 200; ++k) {
    measured = s.angle(theta);
    theta += omega_el * 125e-6;
  }
  theta -= omega_el * 125e-6;
  const double count_el = p * 2.0 * core::kPi / 1024.0;
  const double expected = count_el * std::floor(theta / count_el) - 0.1;
  EXPECT_NEAR(std::remainder(measured - expected, 2 * core::kPi), 0.0, 1e-9);
  // 8 periods of 1 ms span ≈ 0.19 rad: quantisation error at most one count over the window.
  EXPECT_NEAR(s.speed(), omega_el, count_el / (8 * 125e-6) + 1e-9);
}

}  // namespace
}  // namespace rpem::sim
