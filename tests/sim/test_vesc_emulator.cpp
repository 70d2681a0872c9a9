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

#include "rpem/can/vesc.hpp"
#include "rpem/can/vesc_firmware.hpp"
#include "rpem/sim/vesc_motor.hpp"
#include "rpem/sim/vesc_on_demand.hpp"
#include "support/vesc_frames.hpp"

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
    frames.resize(
        vesc::buffer_frames(test::vesc_frames::kHost, test::vesc_frames::kController, 1, {payload.data(), len}, frames));
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
    // Instantaneous values at the read: the PLL's speed (locked on this steady drive: the last row's speed),
    // DC link and winding temperature.
    EXPECT_NEAR(v.erpm, row.sample.omega_el_rad_s * 60.0 / (2.0 * std::numbers::pi), 1.0);
    EXPECT_NEAR(v.v_in_V, row.sample.u_dc_V, 0.1);
    EXPECT_NEAR(v.temp_motor_C, row.sample.t_winding_C, 0.1);
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

// ---- Drive time on demand (sim/vesc_on_demand.hpp): the reads of OnDemandVesc against the same drive
// stepped here one cycle at a time, read at the same instants (independent means, as above).

/// The drive read at chosen instants, independently: every cycle whose start row precedes the instant.
class IndependentReader {
 public:
  IndependentReader() : twin_(short_vesc_scenario()) {}
  /// The means since the previous read (cycles counted in `n`).
  Means read_at(std::int64_t t_ns, int& n) {
    Means sum;
    n = 0;
    while (!started_ || previous_.sample.t_ns < t_ns) {
      io::DriveLogRow row;
      TruthRow truth;
      EXPECT_TRUE(twin_.next(row, truth));
      if (started_) {
        const Means m = cycle_means(previous_, row);
        sum.i_d += m.i_d, sum.i_q += m.i_q, sum.u_d += m.u_d, sum.u_q += m.u_q;
        ++n;
      }
      started_ = true;
      previous_ = row;
    }
    if (n > 0) sum.i_d /= n, sum.i_q /= n, sum.u_d /= n, sum.u_q /= n;
    return sum;
  }

 private:
  DriveSimulator twin_;
  io::DriveLogRow previous_;
  bool started_ = false;
};

void expect_means(const vesc::Values& v, const Means& m, const char* what) {
  EXPECT_NEAR(v.i_d_A, m.i_d, 1e-6) << what;
  EXPECT_NEAR(v.i_q_A, m.i_q, 1e-6) << what;
  EXPECT_NEAR(v.v_d_V, m.u_d, 1e-6) << what;
  EXPECT_NEAR(v.v_q_V, m.u_q, 1e-6) << what;
}

OnDemandVesc::Settings on_demand_settings() {
  OnDemandVesc::Settings s;
  s.motor = {17, 40.0};
  return s;  // statuses 1, 4, 5 at 50 Hz and 2, 3, 6 at 5 Hz
}

TEST(VescOnDemand, APollAfterALongGapAveragesEveryCycleInTheGap) {
  OnDemandVesc drive(short_vesc_scenario(), on_demand_settings());
  IndependentReader reference;
  int n = 0;
  std::vector<std::int64_t> status_times;
  auto emit = [&](const vesc::Status&) { status_times.push_back(drive.time_ns()); };
  ASSERT_TRUE(drive.poll(5'000'000, emit));
  (void)reference.read_at(5'000'000, n);
  // 0.5 s without a poll (a silent bus, or a host that did not run): 6250 cycles of 80 µs.
  const auto late = drive.poll(505'000'000, emit);
  ASSERT_TRUE(late);
  const Means m = reference.read_at(505'000'000, n);
  EXPECT_EQ(n, 6250);
  EXPECT_EQ(late->cycles, n);
  EXPECT_FALSE(late->behind);
  expect_means(late->values, m, "the 0.5 s gap");
  EXPECT_GT(std::abs(late->values.i_q_A), 20.0);  // loaded: not a comparison of zeros
  // Statuses ran on their own drive times through the gap: at 20 ms multiples 1, 4, 5 (25 × 3 up to
  // 500 ms) and at 200 ms multiples 2, 3, 6 (2 × 3), each with the drive within a cycle of its instant.
  ASSERT_EQ(status_times.size(), 25U * 3 + 2U * 3);
  for (const std::int64_t t : status_times) {
    const std::int64_t nearest = (t + 10'000'000) / 20'000'000 * 20'000'000;
    EXPECT_GE(t - nearest, 0);
    EXPECT_LT(t - nearest, 80'000);
  }
}

TEST(VescOnDemand, EachPollOfABurstCoversExactlyItsOwnCycles) {
  // A host that fell behind sees 12 polls at once, sent at 1 kHz: each is read at its own arrival.
  OnDemandVesc drive(short_vesc_scenario(), on_demand_settings());
  IndependentReader reference;
  auto ignore = [](const vesc::Status&) {};
  int n = 0;
  ASSERT_TRUE(drive.poll(20'000'000, ignore));
  (void)reference.read_at(20'000'000, n);
  int total = 0;
  for (int k = 1; k <= 12; ++k) {
    const std::int64_t t = 20'000'000 + k * 1'000'000 + (k % 3) * 37'000;  // jittered arrivals
    const auto r = drive.poll(t, ignore);
    ASSERT_TRUE(r);
    const Means m = reference.read_at(t, n);
    EXPECT_EQ(r->cycles, n) << "poll " << k;
    EXPECT_GE(r->cycles, 11);  // ≈ 12.5 cycles per ms, never 0
    EXPECT_FALSE(r->behind);
    expect_means(r->values, m, "burst");
    total += r->cycles;
  }
  EXPECT_EQ(total, (12'000'000 + 0 * 37'000) / 80'000);  // the last poll (k = 12) has no jitter
  EXPECT_EQ(drive.counters().empty_reads, 0U);
}

TEST(VescOnDemand, APollTheDriveHadPassedIsReadLateButNeverEmpty) {
  OnDemandVesc drive(short_vesc_scenario(), on_demand_settings());
  auto ignore = [](const vesc::Status&) {};
  ASSERT_TRUE(drive.poll(2'000'000, ignore));
  ASSERT_TRUE(drive.run_to(10'000'000, ignore));  // idle running went past a poll not yet seen
  const auto first = drive.poll(6'000'000, ignore);
  ASSERT_TRUE(first);
  EXPECT_TRUE(first->behind);
  EXPECT_EQ(first->cycles, 100);                      // 2 … 10 ms: every cycle run, none lost
  const auto second = drive.poll(7'000'000, ignore);  // also behind, and no cycle since the first
  ASSERT_TRUE(second);
  EXPECT_TRUE(second->behind);
  EXPECT_EQ(second->cycles, 1);  // the reply thread waits for the next control interrupt
  EXPECT_EQ(drive.counters().behind, 2U);
  EXPECT_EQ(drive.counters().empty_reads, 0U);
  // Two pollers within one control cycle (the drive reached 20.08 ms for the first), in order: the
  // firmware's 0/0, faithfully.
  const auto a = drive.poll(20'040'000, ignore);
  const auto b = drive.poll(20'050'000, ignore);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(b->cycles, 0);
  EXPECT_FALSE(b->behind);
  EXPECT_EQ(drive.counters().empty_reads, 1U);
}

}  // namespace
}  // namespace rpem::sim
