// core::machine_plausible and core::within (docs/drive-log.md, "Plausibility limits"): the paper's machine narrows
// current, voltage and speed to ten times its per-unit base (I_b = √2·4.93 A, U_b = √2·400/√3 V, ω_b = 100π rad/s;
// docs/per-unit.md); a value at its limit passes, one a rounding above it does not; NaN is left to the estimator.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>

#include "rpem/core/plausibility.hpp"

namespace rpem::core {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

PlausibleMagnitudes paper_plausible() { return machine_plausible(RatedData{400.0, 4.93, 1000.0, 3}); }

/// The next double above |x|, with x's sign: the smallest step beyond a limit.
double beyond(double x) { return std::nextafter(x, std::copysign(std::numeric_limits<double>::infinity(), x)); }

TEST(Plausibility, TheMachineNarrowsCurrentVoltageAndSpeedToTenTimesItsBase) {
  const PlausibleMagnitudes m = paper_plausible();
  EXPECT_NEAR(m.current_A, 10.0 * std::sqrt(2.0) * 4.93, 1e-12);
  EXPECT_NEAR(m.voltage_V, 10.0 * std::sqrt(2.0) * 400.0 / std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(m.speed_rad_s, 10.0 * 100.0 * M_PI, 1e-9);
  EXPECT_EQ(m.angle_rad, PlausibleMagnitudes{}.angle_rad);
  EXPECT_EQ(m.dc_link_V, PlausibleMagnitudes{}.dc_link_V);  // the inverter's, not the machine's
  // The AX8000 rig (tests/vm/ax8000-vcan.yaml): an AM8141 rated at 34 V line-to-line (10·U_b = 278 V) on a 560 V link.
  DriveSample am8141_on_560V;
  am8141_on_560V.u_dc_V = 560.0;
  EXPECT_TRUE(within(am8141_on_560V, machine_plausible(RatedData{34.0, 8.0, 1000.0, 4})));
  // A name plate beyond the absolute magnitudes never widens them.
  const PlausibleMagnitudes huge = machine_plausible(RatedData{1e5, 1e5, 1e6, 100});
  EXPECT_EQ(huge.current_A, PlausibleMagnitudes{}.current_A);
  EXPECT_EQ(huge.voltage_V, PlausibleMagnitudes{}.voltage_V);
  EXPECT_EQ(huge.speed_rad_s, PlausibleMagnitudes{}.speed_rad_s);
}

TEST(Plausibility, APhaseSampleAtItsLimitsPassesAndOneStepBeyondAnyOfThemDoesNot) {
  const PlausibleMagnitudes m = paper_plausible();
  DriveSample at;
  at.theta_el_rad = -m.angle_rad;
  at.omega_el_rad_s = m.speed_rad_s;
  at.u_dc_V = m.dc_link_V;
  at.u_V = Vec3(m.voltage_V, -m.voltage_V, 0.0);
  at.i_A = Vec3(0.0, m.current_A, -m.current_A);
  EXPECT_TRUE(within(at, m));
  // Each value one step beyond its limit is refused; the same value NaN passes (the estimator's to reject).
  using Field = double& (*)(DriveSample&);
  const Field fields[] = {
      [](DriveSample& s) -> double& { return s.theta_el_rad; }, [](DriveSample& s) -> double& { return s.omega_el_rad_s; },
      [](DriveSample& s) -> double& { return s.u_dc_V; }, [](DriveSample& s) -> double& { return s.u_V[1]; },
      [](DriveSample& s) -> double& { return s.i_A[2]; }};
  for (std::size_t k = 0; k < std::size(fields); ++k) {
    DriveSample s = at;
    double& value = fields[k](s);
    value = beyond(value);
    EXPECT_FALSE(within(s, m)) << "field " << k;
    value = kNaN;
    EXPECT_TRUE(within(s, m)) << "field " << k;
  }
}

TEST(Plausibility, AnAveragedWindowIsHeldToTheSameMagnitudesAndItsTemperaturesToTheirRange) {
  const PlausibleMagnitudes m = paper_plausible();
  AveragedSample at;
  at.i_dq_A = Vec2(-m.current_A, m.current_A);
  at.u_dq_V = Vec2(m.voltage_V, -m.voltage_V);
  at.omega_el_rad_s = -m.speed_rad_s;
  at.omega_el_error_rad_s = m.speed_rad_s;
  at.omega_el_error_noise_rad_s = m.speed_rad_s;
  at.omega_counted_el_rad_s = m.speed_rad_s;
  at.u_dc_V = m.dc_link_V;
  at.t_winding_C = m.temperature_max_C;
  at.t_magnet_C = m.temperature_min_C;
  at.t_drive_C = 25.0;
  at.t_coolant_C = kNaN;  // not reported
  EXPECT_TRUE(within(at, m));
  auto refused = [&](auto change) {
    AveragedSample s = at;
    change(s);
    return !within(s, m);
  };
  EXPECT_TRUE(refused([](AveragedSample& s) { s.i_dq_A[0] = beyond(s.i_dq_A[0]); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.u_dq_V[1] = beyond(s.u_dq_V[1]); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.omega_el_rad_s = beyond(s.omega_el_rad_s); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.omega_el_error_rad_s = beyond(s.omega_el_error_rad_s); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.omega_el_error_noise_rad_s = beyond(s.omega_el_error_noise_rad_s); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.omega_counted_el_rad_s = beyond(s.omega_counted_el_rad_s); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.u_dc_V = beyond(s.u_dc_V); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.t_winding_C = beyond(s.t_winding_C); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.t_magnet_C = beyond(s.t_magnet_C); }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.t_drive_C = 1000.5; }));
  EXPECT_TRUE(refused([](AveragedSample& s) { s.t_coolant_C = -274.0; }));
  // VESC's ERPM is a 32-bit integer: 2^31 rpm, far beyond any drive, is what a corrupted read can carry.
  EXPECT_TRUE(refused([](AveragedSample& s) { s.omega_el_rad_s = 2147483647.0 * 2.0 * M_PI / 60.0; }));
}

}  // namespace
}  // namespace rpem::core
