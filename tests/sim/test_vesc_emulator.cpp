// The emulated VESC without a socket: its replies, as the firmware would send them (can/vesc_firmware),
// decoded by the receiver's side (can/vesc) and compared with the averages of the simulator's own samples
// computed here independently — our own Clarke/Park written out, and the rotor-frame mean of each cycle's
// held stator-frame voltage by 256-point quadrature over the cycle's angle sweep instead of
// cycle_average's closed form — over every control cycle since the previous read, as
// mc_interface_read_reset_avg_id/iq/vd/vq (vedderb/bldc motor/mc_interface.c) keep them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "support/vesc_frames.hpp"
#include "rpem/can/vesc.hpp"
#include "rpem/can/vesc_firmware.hpp"
#include "rpem/sim/vesc_motor.hpp"

namespace rpem::sim {
namespace {

namespace vesc = can::vesc;

Scenario short_vesc_scenario() {
  Scenario s = load_scenario(std::string(RPEM_TEST_SOURCE_DIR) + "/scenarios/vesc-6374.yaml");
  s.duration_s = 0.6;
  s.warmup_s = 0.05;
  return s;
}

/// One control cycle's means, independently: [i_d, i_q, u_d, u_q].
struct Means {
  double i_d = 0, i_q = 0, u_d = 0, u_q = 0;
};

/// Rotor frame of abc values at angle θ (amplitude-invariant Clarke, then Park).
void rotor(const core::Vec3& abc, double th, double& d, double& q) {
  const double al = (2.0 * abc[0] - abc[1] - abc[2]) / 3.0;
  const double be = (abc[1] - abc[2]) / std::sqrt(3.0);
  d = std::cos(th) * al + std::sin(th) * be;
  q = -std::sin(th) * al + std::cos(th) * be;
}

Means cycle_means(const io::DriveLogRow& a, const io::DriveLogRow& b) {
  EXPECT_EQ(a.sample.current_frame, core::Frame::kAbc);
  EXPECT_EQ(a.sample.voltage_frame, core::Frame::kAbc);
  Means m;
  rotor(a.sample.i_A, a.sample.theta_el_rad, m.i_d, m.i_q);
  const double sweep = std::remainder(b.sample.theta_el_rad - a.sample.theta_el_rad, 2.0 * std::numbers::pi);
  constexpr int kPoints = 256;
  for (int k = 0; k < kPoints; ++k) {
    double d = 0, q = 0;
    rotor(a.sample.u_V, a.sample.theta_el_rad + sweep * (k + 0.5) / kPoints, d, q);
    m.u_d += d / kPoints;
    m.u_q += q / kPoints;
  }
  return m;
}

TEST(VescEmulator, RepliesCarryTheAveragesOfEveryCycleSinceThePreviousRead) {
  VescMotor motor(short_vesc_scenario(), {test::vesc_frames::kController, 40.0});
  DriveSimulator twin(short_vesc_scenario());  // the same drive, read independently
  vesc::VescDecoder decoder(test::vesc_frames::kController, test::vesc_frames::kHost);
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> cycles_between(1, 120);  // reads 80 µs … 9.6 ms apart, uneven

  io::DriveLogRow previous, row;
  TruthRow truth;
  ASSERT_TRUE(twin.next(previous, truth));
  ASSERT_TRUE(motor.step());
  std::vector<can::CanFrame> frames(vesc::buffer_frame_count(vesc::kMaxValuesPayload));
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload{};
  int reads = 0;
  double worst_i = 0, worst_u = 0;
  while (reads < 400) {
    const int n = cycles_between(rng);
    Means sum;
    bool ended = false;
    for (int k = 0; k < n; ++k) {
      if (!motor.step() || !twin.next(row, truth)) {
        ended = true;
        break;
      }
      const Means m = cycle_means(previous, row);
      sum.i_d += m.i_d, sum.i_q += m.i_q, sum.u_d += m.u_d, sum.u_q += m.u_q;
      previous = row;
    }
    if (ended) break;
    ASSERT_EQ(motor.cycles_since_read(), n);
    const std::size_t len = vesc::encode_values(motor.read_values(), vesc::kEstimatorMask, payload);
    frames.resize(vesc::buffer_frame_count(len));
    frames.resize(vesc::buffer_frames(test::vesc_frames::kHost, test::vesc_frames::kController, 1, {payload.data(), len}, frames));
    vesc::VescDecoder::Event last = vesc::VescDecoder::Event::kNone;
    for (const auto& f : frames) last = decoder.decode(f);
    ASSERT_EQ(last, vesc::VescDecoder::Event::kValues);
    const vesc::Values& v = decoder.values();
    // Quantisation of the reply: 0.01 A, 1 mV (truncation); the quadrature is exact to ~1e-9 here.
    worst_i = std::max({worst_i, std::abs(v.i_d_A - sum.i_d / n), std::abs(v.i_q_A - sum.i_q / n)});
    worst_u = std::max({worst_u, std::abs(v.v_d_V - sum.u_d / n), std::abs(v.v_q_V - sum.u_q / n)});
    EXPECT_NEAR(v.i_q_A, sum.i_q / n, 0.0101) << "read " << reads;
    EXPECT_NEAR(v.i_d_A, sum.i_d / n, 0.0101) << "read " << reads;
    EXPECT_NEAR(v.v_d_V, sum.u_d / n, 0.00101) << "read " << reads;
    EXPECT_NEAR(v.v_q_V, sum.u_q / n, 0.00101) << "read " << reads;
    // Instantaneous values at the read: the last row's speed, DC link and winding temperature.
    EXPECT_NEAR(v.erpm, row.sample.omega_el_rad_s * 60.0 / (2.0 * std::numbers::pi), 1.0);
    EXPECT_NEAR(v.v_in_V, row.sample.u_dc_V, 0.1);
    EXPECT_NEAR(v.temp_motor_C, row.t_winding_C.value(), 0.1);
    EXPECT_NEAR(v.temp_fet_C, 40.0, 1e-9);
    ++reads;
  }
  EXPECT_GE(reads, 50);
  EXPECT_EQ(decoder.counters().replies, static_cast<std::uint64_t>(reads));
  EXPECT_EQ(decoder.counters().crc_error, 0U);
  // The drive is loaded (≈ 31 A at 1.5 Nm), so the comparison is not of zeros.
  EXPECT_GT(std::abs(decoder.values().i_q_A), 20.0);
  RecordProperty("worst_current_error_A", std::to_string(worst_i));
  RecordProperty("worst_voltage_error_V", std::to_string(worst_u));
}

TEST(VescEmulator, ASecondReadRightAfterTheFirstFindsNoCycleAndReportsZero) {
  VescMotor motor(short_vesc_scenario(), {17, 40.0});
  ASSERT_TRUE(motor.advance_to(5'000'000));
  const vesc::Values first = motor.read_values();  // the rightful poller
  EXPECT_GT(std::abs(first.i_q_A), 20.0);
  EXPECT_EQ(motor.cycles_since_read(), 0);
  const vesc::Values stolen = motor.read_values();  // a second poller right after: 0/0 in the firmware
  EXPECT_TRUE(std::isnan(stolen.i_q_A));
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload{};
  const std::size_t len = vesc::encode_values(stolen, vesc::bit(vesc::kIq), payload);
  vesc::Values decoded;
  ASSERT_EQ(vesc::parse_values({payload.data(), len}, decoded), vesc::ParseResult::kOk);
  EXPECT_EQ(decoded.i_q_A, 0.0);  // the Cortex-M4's cast of NaN
}

TEST(VescEmulator, StatusBroadcastsCarryTheInstantaneousState) {
  VescMotor motor(short_vesc_scenario(), {17, 40.0});
  ASSERT_TRUE(motor.advance_to(100'000'000));
  vesc::VescDecoder decoder(17, 0x7D);
  ASSERT_EQ(decoder.decode(vesc::status_frame(motor.status(1))), vesc::VescDecoder::Event::kStatus);
  EXPECT_NEAR(decoder.status().erpm, 3000.0 * 7, 30.0);  // 3000 rpm, 7 pole pairs
  ASSERT_EQ(decoder.decode(vesc::status_frame(motor.status(4))), vesc::VescDecoder::Event::kStatus);
  EXPECT_NEAR(decoder.status().temp_fet_C, 40.0, 0.1);
  EXPECT_NEAR(decoder.status().temp_motor_C, 30.0, 0.5);  // the scenario's start, warming slowly
  ASSERT_EQ(decoder.decode(vesc::status_frame(motor.status(5))), vesc::VescDecoder::Event::kStatus);
  EXPECT_NEAR(decoder.status().v_in_V, 48.0, 0.1);
  // 0.1 s at 21000 ERPM: 35 electrical revolutions, 6 steps each.
  EXPECT_NEAR(decoder.status().tachometer, 6 * 35, 6);
  EXPECT_EQ(motor.cycles_since_read(), 1250);  // statuses read no average
}

}  // namespace
}  // namespace rpem::sim
