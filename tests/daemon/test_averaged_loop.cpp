// The estimator loop on an averaged source (source: vesc, rotor-frame signal maps): averaged rotor-frame
// samples at uneven host timestamps step AveragedDriveEstimator, one per received sample, whatever the
// loop period; silence makes the estimates stale and the chain restart; samples of the other kind are
// counted and not stepped. Data: the machine equations averaged over each window (support/averaged_data.hpp).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "rpem/core/clock.hpp"
#include "rpem/daemon/loop_thread.hpp"
#include "support/averaged_data.hpp"
#include "support/loop_queues.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/paper_thermal.hpp"

namespace rpem::daemon {
namespace {

struct AveragedRig {
  DaemonConfig config = builtin_daemon_config();
  test::LoopQueues queues = test::loop_queues(16384, 16, 65536);
  SpscQueue<SourceSample>::Producer& input = queues.input;
  SpscQueue<Report>::Consumer& output = queues.output;
  std::unique_ptr<LoopThread> loop;
  test::AveragedDataGenerator gen;
  std::int64_t now_ns = 1'000'000'000;
  std::int64_t pushed = 0;
  std::vector<std::int64_t> push_ns;  ///< the loop's time at which each window was pushed (and stepped)
  bool have_next = false;
  core::AveragedSample next;
  double t_winding_C = std::numeric_limits<double>::quiet_NaN();  ///< the drive's winding sensor on every window
  double t_coolant_C = std::numeric_limits<double>::quiet_NaN();  ///< its coolant sensor, on every coolant_every-th
  int coolant_every = 1;                                          ///< window (NaN on the others)

  /// `configure` changes the configuration before the loop is made.
  explicit AveragedRig(
      double rate_Hz, double psi_scale = 1.0, bool angle_source_assumed = false,
      const std::function<void(DaemonConfig&)>& configure = [](DaemonConfig&) {}) {
    config.fixed.source = VescSource::Options{};
    config.live.machine.estimator.regimes.angle_source_assumed = angle_source_assumed;
    configure(config);
    loop = std::make_unique<LoopThread>(config, std::move(queues.loop));
    gen.base = test::paper_base();
    gen.plant = test::paper_machine_pu();
    gen.plant.psi_m_pu *= psi_scale;
    gen.rate_Hz = rate_Hz;
    const core::Vec2 i = core::mtpa_reference(gen.plant, 0.4);
    gen.n_pu = [](double) { return 0.5; };
    gen.i_pu = [i](double) { return i; };
  }
  /// `seconds` of the drive's time: every millisecond the loop runs over the windows that closed.
  void run(double seconds) {
    const std::int64_t end_ns = now_ns + static_cast<std::int64_t>(seconds * 1e9);
    while (now_ns < end_ns) {
      now_ns += 1'000'000;
      while (true) {
        if (!have_next) {
          next = gen.next();
          next.t_start_ns += 1'000'000'000;  // host time: the windows start when the loop does
          next.t_ns += 1'000'000'000;
          next.t_winding_C = t_winding_C;
          next.t_coolant_C = pushed % coolant_every == 0 ? t_coolant_C : std::numeric_limits<double>::quiet_NaN();
          have_next = true;
        }
        if (next.t_ns > now_ns) break;
        ASSERT_TRUE(input.push(next));
        ++pushed;
        push_ns.push_back(now_ns);
        have_next = false;
      }
      loop->process(now_ns);
    }
  }
  /// Silence: the drive's time runs on without samples (the generator skips the windows).
  void silence(double seconds) {
    const std::int64_t end_ns = now_ns + static_cast<std::int64_t>(seconds * 1e9);
    while (now_ns < end_ns) {
      now_ns += 1'000'000;
      loop->process(now_ns);
    }
    while (gen.t_s + 1.0 < core::to_seconds(now_ns)) (void)gen.next();
    have_next = false;
  }
  EstimateReport estimate;
  MeasurementReport measurement;
  LoopStatsReport stats;
  /// Keeps the newest report of each kind.
  void drain() {
    Report r;
    while (output.pop(r)) {
      if (auto* e = std::get_if<EstimateReport>(&r)) estimate = *e;
      if (auto* m = std::get_if<MeasurementReport>(&r)) measurement = *m;
      if (auto* s = std::get_if<LoopStatsReport>(&r)) stats = *s;
    }
  }
};

TEST(AveragedLoop, TheSourceNamesTheEstimator) {
  DaemonConfig c = builtin_daemon_config();
  EXPECT_EQ(SourceCatalogue::sample_kind(c.fixed.source), SampleKind::kPhase);
  c.fixed.source = VescSource::Options{};
  EXPECT_EQ(SourceCatalogue::sample_kind(c.fixed.source), SampleKind::kAveraged);
}

// At 50, 200 and 1000 Hz with ±30 % jitter, every window is stepped once and ψm converges to the truth
// (8 % below the configuration) as the averaged estimator alone does (tests/core/test_averaged_estimator).
class AtRate : public ::testing::TestWithParam<double> {};

TEST_P(AtRate, EveryWindowIsSteppedOnceAndPsiMConverges) {
  AveragedRig rig(GetParam(), 0.92);
  rig.run(20.0);
  rig.drain();
  const EstimateReport& e = rig.estimate;
  EXPECT_EQ(e.state, DaemonState::kRunning);
  EXPECT_LE(e.samples, rig.pushed);  // estimates are reported every 100 ms
  EXPECT_GE(e.samples, rig.pushed - static_cast<std::int64_t>(0.13 * GetParam()) - 1);
  EXPECT_NEAR(e.psi_m_Wb / (0.92 * 1.14), 1.0, 1e-2);
  EXPECT_TRUE(e.psi_m_adapting);
  EXPECT_GE(e.newest_rx_ns, rig.now_ns - static_cast<std::int64_t>(0.1e9 + 2e9 / GetParam()));  // the window's end
  EXPECT_EQ(e.sample_time_us, e.newest_rx_ns / 1000);  // an averaged sample's time is its host timestamp
  const LoopStatsReport& s = rig.stats;
  EXPECT_EQ(s.rows.get(&diagnostics_t::samples_wrong_kind), 0);
  EXPECT_EQ(s.rows.get(&diagnostics_t::resyncs), 1);  // the first window only anchors the chain
}

// A machine file that does not say where the frame comes from: beside the regimes, RPEM_DIAGNOSTICS counts the windows
// whose R_s excitation rests on the sensor's frame assumed in its place. At 0.015 pu with |i| = 1 pu the paper
// machine's R_s term stands out on a sensor's frame (r_min·|i| = 0.0213 against |n|·(Δψ + Δx·|i|) = 0.0144 pu) and not
// on a sensorless one, whose error the lock test cannot bound at that back EMF (|n|·F = 0.015·2.55 pu more:
// docs/derivations.md §13): every window that excites R_s is one of them; a file that says sensor counts none, and
// both decide alike.
TEST(AveragedLoop, WindowsThatExciteRsOnlyOnAnAssumedFrameAreCounted) {
  std::array<std::int64_t, 2> excited{};
  for (const bool assumed : {false, true}) {
    AveragedRig rig(200.0, 1.0, assumed);
    rig.gen.n_pu = [](double) { return 0.015; };
    rig.gen.i_pu = [](double) { return core::Vec2(0.0, 1.0); };
    rig.run(5.0);
    rig.drain();
    const LoopStatsReport& s = rig.stats;
    excited[assumed ? 1 : 0] =
        s.rows.get(&diagnostics_t::regime_excites_r_s) + s.rows.get(&diagnostics_t::regime_excites_both);
    EXPECT_EQ(s.rows.get(&diagnostics_t::r_s_on_assumed_frame), assumed ? excited[1] : 0) << assumed;
  }
  EXPECT_GT(excited[1], 500);  // 5 s of 200 Hz windows
  EXPECT_EQ(excited[0], excited[1]);
}

INSTANTIATE_TEST_SUITE_P(Rates, AtRate, ::testing::Values(50.0, 200.0, 1000.0),
                         [](const auto& p) { return std::to_string(static_cast<int>(p.param)) + "Hz"; });

// ψm is identified in averaged time, not in samples: the validity tracker counts each window's interval
// (rather than the native period), so identification takes the same seconds at 50 and at 1000 Hz.
TEST(AveragedLoop, ValidityCountsTheIntervalsNotTheSamples) {
  for (double rate : {50.0, 1000.0}) {
    AveragedRig rig(rate);
    ASSERT_EQ(rig.config.live.validity.psi_m_after_s, 1.0);
    rig.run(0.7);
    rig.drain();
    EXPECT_FALSE(rig.estimate.psi_m_valid) << rate << " Hz";
    rig.run(0.6);
    rig.drain();
    EXPECT_TRUE(rig.estimate.psi_m_valid) << rate << " Hz";
  }
}

// Silence longer than daemon.stale_timeout_s (the controller stopped answering): estimates held and
// flagged stale; the first window after it restarts the chain (adapts nothing), then adaptation resumes.
TEST(AveragedLoop, SilenceIsStaleAndTheNextWindowRestartsTheChain) {
  AveragedRig rig(200.0, 0.92);
  rig.run(3.0);
  rig.silence(0.3);
  rig.drain();
  const double held = rig.estimate.psi_m_Wb;
  rig.silence(0.3);
  rig.drain();
  const EstimateReport stale = rig.estimate;
  EXPECT_EQ(stale.state, DaemonState::kStale);
  EXPECT_EQ(stale.psi_m_Wb, held);
  EXPECT_FALSE(stale.psi_m_adapting);
  rig.run(1.0);
  rig.drain();
  EXPECT_EQ(rig.estimate.state, DaemonState::kRunning);
  EXPECT_EQ(rig.stats.rows.get(&diagnostics_t::resyncs), 2);
}

// The stream broken off ends the chain, and its last window — never judged for a bridge release inside it — is taken
// back (docs/derivations.md §13, "A chain's last window"). Its adaptation is taken back in the validity tracker too:
// once stale, ψm's age counts from the window before it, whose value the estimate is again.
TEST(AveragedLoop, AWindowTakenBackAtTheStreamsEndNoLongerCountsAsAdapted) {
  AveragedRig rig(200.0, 0.92);
  rig.run(3.0);
  rig.drain();
  ASSERT_TRUE(rig.estimate.psi_m_adapting);
  ASSERT_GE(rig.push_ns.size(), 2U);
  const std::int64_t last_ns = rig.push_ns.back(), before_last_ns = rig.push_ns[rig.push_ns.size() - 2];
  ASSERT_GT(last_ns - before_last_ns, 2'000'000);  // 200 Hz windows on 1 ms ticks: 4–6 ms apart
  // Tick by tick through the silence: each report's age against the loop's time of the tick that made it.
  bool stale_seen = false;
  for (int tick = 0; tick < 600 && !stale_seen; ++tick) {
    rig.now_ns += 1'000'000;
    rig.loop->process(rig.now_ns);
    Report r;
    while (rig.output.pop(r)) {
      const auto* e = std::get_if<EstimateReport>(&r);
      if (e == nullptr) continue;
      const std::int64_t adapted_ns = e->state == DaemonState::kStale ? before_last_ns : last_ns;
      EXPECT_NEAR(e->psi_m_age_s, core::to_seconds(rig.now_ns - adapted_ns), 1e-9)
          << "state " << static_cast<int>(e->state) << " at tick " << tick;
      stale_seen = stale_seen || e->state == DaemonState::kStale;
    }
  }
  EXPECT_TRUE(stale_seen);
}

TEST(AveragedLoop, MeasurementsCarryTheDrivesSensorsAndNoAngle) {
  AveragedRig rig(200.0);
  rig.gen.plant = test::paper_machine_pu();
  rig.run(0.1);
  rig.drain();
  EXPECT_TRUE(std::isnan(rig.measurement.t_drive_sensor_C));  // no reading yet: neither a value nor an age
  EXPECT_TRUE(std::isnan(rig.measurement.t_drive_sensor_age_s));
  core::AveragedSample s = rig.gen.next();
  s.t_start_ns = rig.now_ns;
  s.t_ns = rig.now_ns + 4'000'000;
  s.t_winding_C = 71.5;
  s.t_drive_C = 42.0;
  s.t_coolant_C = 18.25;
  ASSERT_TRUE(rig.input.push(s));
  rig.now_ns += 200'000'000;
  rig.loop->process(rig.now_ns);
  rig.drain();
  const MeasurementReport& m = rig.measurement;
  EXPECT_EQ(m.t_winding_sensor_C, 71.5);
  EXPECT_EQ(m.t_drive_sensor_C, 42.0);
  EXPECT_EQ(m.t_coolant_sensor_C, 18.25);
  EXPECT_EQ(m.t_winding_sensor_age_s, 0.0);  // read on the very sample the measurement is of
  EXPECT_EQ(m.t_coolant_sensor_age_s, 0.0);
  EXPECT_TRUE(std::isnan(m.theta_el_rad));
  EXPECT_EQ(m.sample_time_us, s.t_ns / 1000);
}

/// An AveragedRig's configuration change: the paper machine's network (support/paper_thermal.hpp) at `coolant_C`, active.
std::function<void(DaemonConfig&)> with_network(double coolant_C) {
  return [coolant_C](DaemonConfig& c) {
    c.live.thermal = test::paper_thermal_fusion();
    c.live.thermal.coolant_C = coolant_C;
    c.live.thermal_active = true;
  };
}

// A drive's winding sensor (a VESC's temp_motor, a signal map's T_winding) reaches the loop's thermal fusion
// (docs/thermal.md, "In rpemd"): a machine 35 K above its coolant at rpemd's start is found unsoaked by the first
// reading and the winding follows the sensor, observed in every filter step; when the sensor stops reporting (a
// VESC's −100 °C, read as no reading) the winding is predicted and its observation ages. At 0.5 pu r̂s does not
// adapt, so the sensor is the winding's only observation.
TEST(AveragedLoop, TheDrivesWindingSensorIsFusedAndItsSilenceIsPredicted) {
  constexpr double kCoolant_C = 40.0, kSensor_C = 75.0;
  AveragedRig rig(200.0, 1.0, false, with_network(kCoolant_C));
  const double sensor_sigma_K = rig.config.live.thermal.winding_sensor_sigma_K;
  ASSERT_GT(sensor_sigma_K, 0.0);  // the network's settings fuse a winding sensor
  rig.t_winding_C = kSensor_C;
  rig.run(10.0);
  rig.drain();
  const EstimateReport observed = rig.estimate;
  ASSERT_TRUE(observed.thermal_active);
  EXPECT_EQ(observed.t_winding_source, mirror::estimate_t::SOURCE_OBSERVED);
  EXPECT_GE(observed.t_winding_observed_age_s, 0.0);
  EXPECT_LE(observed.t_winding_observed_age_s, 1.5);  // the filter's step (1 s) and the report's spacing
  // Ten readings of σ_s at one value: the fused winding within 3 of its own σ of them, that σ no wider than one
  // reading's. A soaked start (the coolant, σ = initial_sigma_K) could not be there after ten readings of 1 K.
  EXPECT_LE(observed.t_winding_fused_sd_C, sensor_sigma_K);
  EXPECT_NEAR(observed.t_winding_fused_C, kSensor_C, 3.0 * observed.t_winding_fused_sd_C);
  EXPECT_EQ(rig.measurement.t_winding_sensor_C, kSensor_C);

  rig.t_winding_C = std::numeric_limits<double>::quiet_NaN();
  rig.run(20.0);
  rig.drain();
  const EstimateReport predicted = rig.estimate;
  EXPECT_EQ(predicted.t_winding_source, mirror::estimate_t::SOURCE_PREDICTED);
  EXPECT_GE(predicted.t_winding_observed_age_s, 19.0);
  EXPECT_LE(predicted.t_winding_observed_age_s, 21.5);
  EXPECT_GT(predicted.t_winding_fused_sd_C, observed.t_winding_fused_sd_C);  // the band widens without readings
  // RPEM_MEASUREMENT keeps the newest reading and says how old it is: 20 s of the windows' time, within the
  // measurement's decimation (10 ms at 100 Hz) and a window either side (at most 6.5 ms: 5 ms ± 30 % jitter).
  EXPECT_EQ(rig.measurement.t_winding_sensor_C, kSensor_C);
  EXPECT_GE(rig.measurement.t_winding_sensor_age_s, 20.0 - 0.01 - 2 * 0.0065);
  EXPECT_LE(rig.measurement.t_winding_sensor_age_s, 20.0 + 2 * 0.0065);
}

// A drive's coolant sensor (a signal map's T_coolant) is the network's boundary in place of thermal.coolant_C
// (docs/thermal.md, "In rpemd"). Read on one window in 50 (a coolant frame at 4 Hz beside currents at 200 Hz), each
// reading holds until the next, so a filter step's coolant is the reading; without the hold it would be 1/50 of the
// reading and 49/50 of the configured 40 °C (39.65 °C).
TEST(AveragedLoop, TheDrivesCoolantSensorIsTheNetworksBoundaryAndHolds) {
  constexpr double kConfigured_C = 40.0, kMeasured_C = 22.5;
  AveragedRig rig(200.0, 1.0, false, with_network(kConfigured_C));
  rig.run(3.0);  // no coolant reading yet: the configured one
  rig.drain();
  ASSERT_TRUE(rig.estimate.thermal_active);
  EXPECT_DOUBLE_EQ(rig.estimate.thermal.load.coolant_C, kConfigured_C);
  rig.t_coolant_C = kMeasured_C;
  rig.coolant_every = 50;
  rig.run(3.0);  // the newest 1 s step lies wholly after the first reading
  rig.drain();
  EXPECT_NEAR(rig.estimate.thermal.load.coolant_C, kMeasured_C, 1e-9);
  // RPEM_MEASUREMENT shows the coolant read on one window in 50 on every measurement, no older than 49 windows
  // (each at most 6.5 ms: 5 ms ± 30 % jitter), though the window it is decimated from has no reading 49 times in 50.
  EXPECT_EQ(rig.measurement.t_coolant_sensor_C, kMeasured_C);
  EXPECT_GE(rig.measurement.t_coolant_sensor_age_s, 0.0);
  EXPECT_LE(rig.measurement.t_coolant_sensor_age_s, 49 * 0.0065);
}

TEST(AveragedLoop, APhaseSampleIsCountedNotStepped) {
  AveragedRig rig(200.0);
  rig.run(0.5);
  const std::int64_t stepped = rig.pushed;
  test::ModelDataGenerator phase;
  phase.plant = test::paper_machine_pu();
  phase.omega_n_rad_s = test::paper_base().omega_el_rad_s;
  std::int64_t t = 0;
  ASSERT_TRUE(rig.input.push(phase.next_si(test::paper_base(), t)));
  rig.now_ns += 1'000'000'000;
  rig.loop->process(rig.now_ns);
  rig.drain();
  EXPECT_EQ(rig.estimate.samples, stepped);
  EXPECT_EQ(rig.stats.rows.get(&diagnostics_t::samples_wrong_kind), 1);
}

// A window holding a value no drive of this machine produces is counted and not estimated on, and the next window
// starts a new chain (core::within; docs/rpemd.md, "Values no drive produces"): a speed of 2^31 ERPM (VESC's 32-bit field, as a
// corrupted read or a wrong scale in a signal map gives it) and a winding sensor at 3276.7 °C (VESC's 16-bit
// temperature field at its maximum). ψm converges as it does without them.
TEST(AveragedLoop, AWindowBeyondWhatTheMachineProducesIsCountedAndNotEstimatedOn) {
  AveragedRig rig(200.0, 0.92);
  rig.run(5.0);
  auto change_next = [&](auto change) {  // the next window the rig pushes, in its turn
    if (!rig.have_next) {
      rig.next = rig.gen.next();
      rig.next.t_start_ns += 1'000'000'000;
      rig.next.t_ns += 1'000'000'000;
      rig.have_next = true;
    }
    change(rig.next);
    rig.run(5.0);
  };
  change_next([](core::AveragedSample& w) { w.omega_el_rad_s = 2147483647.0 * 2.0 * M_PI / 60.0; });
  change_next([](core::AveragedSample& w) { w.t_winding_C = 3276.7; });
  rig.run(5.0);
  rig.drain();
  const LoopStatsReport& s = rig.stats;
  EXPECT_EQ(s.rows.get(&diagnostics_t::rejected_implausible), 2);
  EXPECT_EQ(s.rows.get(&diagnostics_t::resyncs), 3);  // the first window, and the one after each left out
  EXPECT_EQ(s.rows.get(&diagnostics_t::rejected_non_finite), 0);
  EXPECT_LE(rig.estimate.samples, rig.pushed - 2);
  EXPECT_NEAR(rig.estimate.psi_m_Wb / (0.92 * 1.14), 1.0, 1e-2);
}

}  // namespace
}  // namespace rpem::daemon
