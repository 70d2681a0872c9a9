// The estimator loop's period work (process()) without threads: samples in, reports out; stale
// detection; commands; validity and age; derived temperatures.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/daemon/loop_thread.hpp"
#include "support/loop_queues.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"

namespace rpem::daemon {
namespace {

Command command(Command::Kind kind, std::int64_t seq, double psi_m_Wb = 0.0, double r_s_Ohm = 0.0) {
  Command c;
  c.kind = kind;
  c.seq = seq;
  c.psi_m_Wb = psi_m_Wb;
  c.r_s_Ohm = r_s_Ohm;
  return c;
}

struct Rig {
  DaemonConfig config = builtin_daemon_config();
  SpscQueue<SourceSample>::Producer input;
  SpscQueue<Command>::Producer commands;
  SpscQueue<Report>::Consumer output;
  std::unique_ptr<LoopThread> loop;
  test::ModelDataGenerator gen;
  core::PerUnitBase base = test::paper_base();
  std::int64_t t_ns = 0;
  std::int64_t now_ns = 1'000'000'000;

  Rig() {
    rebuild();
    gen.plant = test::paper_machine_pu();
    gen.omega_n_rad_s = base.omega_el_rad_s;
  }
  /// A new loop with the (changed) configuration, and new queues to it.
  void rebuild() {
    test::LoopQueues queues = test::loop_queues(16384, 16, 65536);
    loop = std::make_unique<LoopThread>(config, std::move(queues.loop));
    input = std::move(queues.input);
    commands = std::move(queues.commands);
    output = std::move(queues.output);
  }
  /// Feeds `seconds` of samples, processing every millisecond as the loop would.
  void run(double seconds) {
    const int ms = static_cast<int>(seconds * 1000);
    for (int k = 0; k < ms; ++k) {
      for (int s = 0; s < 8; ++s) ASSERT_TRUE(input.push(gen.next_si(base, t_ns)));
      now_ns += 1'000'000;
      loop->process(now_ns);
    }
  }
  void idle(double seconds) {
    for (int k = 0; k < static_cast<int>(seconds * 1000); ++k) {
      now_ns += 1'000'000;
      loop->process(now_ns);
    }
  }
  /// The newest report of one kind (the others are dropped).
  template <class Kind>
  Kind last() {
    Kind newest;
    Report r;
    while (output.pop(r)) {
      if (auto* k = std::get_if<Kind>(&r)) newest = *k;
    }
    return newest;
  }
  EstimateReport last_estimate() { return last<EstimateReport>(); }
  LoopStatsReport last_stats() { return last<LoopStatsReport>(); }
};

TEST(EstimatorLoop, SamplesBecomeEstimatesThatConverge) {
  Rig rig;
  rig.gen.plant.psi_m_pu *= 0.92;
  rig.gen.n_pu = 0.4;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.4);
  rig.run(8.0);
  const EstimateReport e = rig.last_estimate();
  EXPECT_EQ(e.state, DaemonState::kRunning);
  EXPECT_GT(e.samples, 64000 - 800);  // estimates are reported every 100 ms
  EXPECT_LE(e.samples, 64000);
  EXPECT_NEAR(e.psi_m_Wb / (0.92 * 1.14), 1.0, 2e-3);
  EXPECT_TRUE(e.psi_m_adapting);
  EXPECT_TRUE(e.psi_m_valid);
  EXPECT_TRUE(e.psi_m_converged);
  EXPECT_FALSE(e.r_s_valid);
  EXPECT_FALSE(e.r_s_converged);  // held at its initial value all along: still, but not converged to anything
  // ψm −8 % at −0.12 %/K: T_magnet = 20 + (0.92 − 1)/(−0.0012) ≈ 86.7 °C.
  EXPECT_NEAR(e.t_magnet_C, 20.0 + (e.psi_m_Wb / 1.14 - 1.0) / -0.0012, 1e-9);
  EXPECT_NEAR(e.t_magnet_C, 86.7, 1.0);
  EXPECT_TRUE(e.has_good_psi_m);
}

TEST(EstimatorLoop, RsBecomesValidAfterStandstillAdaptationAndStaysValid) {
  Rig rig;
  rig.gen.plant.r_s_pu *= 1.1;
  rig.gen.n_pu = 0.0;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.4);
  rig.run(1.0);
  EXPECT_FALSE(rig.last_estimate().r_s_valid);
  rig.run(19.0);
  EstimateReport e = rig.last_estimate();
  EXPECT_TRUE(e.r_s_valid);
  EXPECT_NEAR(e.r_s_Ohm / (1.1 * 2.25), 1.0, 3e-3);
  EXPECT_NEAR(e.t_winding_C, 20.0 + 0.1 / 0.00393, 1.0);
  rig.gen.n_pu = 0.4;
  rig.run(1.0);
  e = rig.last_estimate();
  EXPECT_TRUE(e.r_s_valid);  // held once r_s has been identified
  EXPECT_FALSE(e.r_s_adapting);
  EXPECT_NEAR(e.r_s_age_s, 1.0, 0.11);  // held since the speed step, one report interval of resolution
}

// eq:GainSchedule: r_s adapts only below n_lim,2 — at the speed step it stops and its value is held.
// The age is the time since the last sample in which it adapted; past validity.max_hold_s the held
// value is no longer valid, until r_s adapts again.
TEST(EstimatorLoop, HeldValuesSayHowOldTheyAreAndLapseAfterMaxHold) {
  Rig rig;
  rig.config.live.validity.max_hold_s = 3.0;
  rig.rebuild();
  rig.gen.plant.r_s_pu *= 1.05;
  rig.gen.n_pu = 0.0;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.4);
  rig.run(5.0);
  EstimateReport e = rig.last_estimate();
  EXPECT_TRUE(e.r_s_adapting);
  EXPECT_TRUE(e.r_s_valid);
  EXPECT_NEAR(e.r_s_age_s, 0.0, 1e-3);    // adapted in this period
  EXPECT_DOUBLE_EQ(e.psi_m_age_s, -1.0);  // ψm has never adapted: the configured initial value
  EXPECT_FALSE(e.psi_m_valid);
  EXPECT_FALSE(e.psi_m_converged);

  rig.gen.n_pu = 0.4;
  rig.run(2.0);
  e = rig.last_estimate();
  EXPECT_FALSE(e.r_s_adapting);
  EXPECT_NEAR(e.r_s_age_s, 2.0, 0.11);
  EXPECT_TRUE(e.r_s_valid);
  EXPECT_TRUE(e.psi_m_adapting);
  EXPECT_TRUE(e.psi_m_valid);  // after validity.psi_m_after_s (1 s) of adaptation
  const double held = e.r_s_Ohm;

  rig.run(2.0);
  e = rig.last_estimate();
  EXPECT_NEAR(e.r_s_age_s, 4.0, 0.11);
  EXPECT_FALSE(e.r_s_valid);  // older than max_hold_s
  EXPECT_DOUBLE_EQ(e.r_s_Ohm, held);

  rig.gen.n_pu = 0.0;
  rig.run(0.5);
  e = rig.last_estimate();
  EXPECT_TRUE(e.r_s_adapting);
  EXPECT_TRUE(e.r_s_valid);  // identified before, adapting again
  EXPECT_FALSE(e.psi_m_adapting);
  EXPECT_NEAR(e.psi_m_age_s, 0.5, 0.11);
  EXPECT_TRUE(e.psi_m_valid);
}

TEST(EstimatorLoop, NewInitialValuesStartIdentificationOver) {
  Rig rig;
  rig.gen.n_pu = 0.0;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.4);
  rig.run(3.0);
  ASSERT_TRUE(rig.last_estimate().r_s_valid);
  ASSERT_TRUE(rig.commands.push(command(Command::Kind::kSetValues, 1, 1.1, 2.4)));
  rig.gen.n_pu = 0.4;  // r_s cannot adapt: it stays at the set value, never adapted
  rig.run(0.5);
  const EstimateReport e = rig.last_estimate();
  EXPECT_DOUBLE_EQ(e.r_s_Ohm, 2.4);
  EXPECT_DOUBLE_EQ(e.r_s_age_s, -1.0);
  EXPECT_FALSE(e.r_s_valid);
}

TEST(EstimatorLoop, SeededValuesCarryTheirAgeFromTheStateFile) {
  Rig rig;
  rig.loop->seed(SeedValue{1.12, 30.0}, SeedValue{2.3, 5.0}, rig.now_ns);
  rig.idle(0.05);  // one estimate report, in the first period: 1 ms after the seed
  const EstimateReport e = rig.last_estimate();
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.12);
  EXPECT_DOUBLE_EQ(e.r_s_Ohm, 2.3);
  EXPECT_NEAR(e.r_s_age_s, 5.001, 1e-9);
  EXPECT_TRUE(e.r_s_valid);  // identified before the restart, 5 s old
  EXPECT_NEAR(e.psi_m_age_s, 30.001, 1e-9);
  EXPECT_FALSE(e.psi_m_valid);    // older than max_hold_s (20 s)
  EXPECT_TRUE(e.has_good_psi_m);  // still what the state file keeps until a better value comes
  EXPECT_NEAR(e.good_r_s_age_s, 5.001, 1e-9);
}

TEST(EstimatorLoop, AReloadReachesTheLoopAsOneObject) {
  Rig rig;
  rig.gen.n_pu = 0.0;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.4);
  rig.run(3.0);
  rig.gen.n_pu = 0.4;
  rig.run(1.5);
  ASSERT_TRUE(rig.last_estimate().r_s_valid);
  Command reload;
  reload.kind = Command::Kind::kReconfigure;
  reload.live = rig.config.live;
  reload.live.validity.max_hold_s = 1.0;
  reload.live.temperature.r_s.reference_C = 40.0;
  ASSERT_TRUE(rig.commands.push(reload));
  rig.run(0.2);
  const EstimateReport e = rig.last_estimate();
  EXPECT_FALSE(e.r_s_valid);  // held 1.7 s > the reloaded 1 s
  EXPECT_NEAR(e.t_winding_C, 40.0 + (e.r_s_Ohm / 2.25 - 1.0) / 0.00393, 1e-9);
}

TEST(EstimatorLoop, NoSamplesMeansStaleWithEstimatesHeldThenRecovery) {
  Rig rig;
  rig.gen.n_pu = 0.4;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.2);
  rig.run(1.0);
  const EstimateReport before = rig.last_estimate();
  rig.idle(0.5);
  const EstimateReport stale = rig.last_estimate();
  EXPECT_EQ(stale.state, DaemonState::kStale);
  EXPECT_EQ(stale.psi_m_Wb, before.psi_m_Wb);
  EXPECT_FALSE(stale.psi_m_adapting);  // held, and saying since when
  EXPECT_NEAR(stale.psi_m_age_s, 0.5, 0.11);
  rig.run(0.5);
  EXPECT_EQ(rig.last_estimate().state, DaemonState::kRunning);
}

TEST(EstimatorLoop, CommandsFreezeSetResetAndReconfigure) {
  Rig rig;
  rig.gen.plant.psi_m_pu *= 0.9;
  rig.gen.n_pu = 0.4;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.3);
  ASSERT_TRUE(rig.commands.push(command(Command::Kind::kFreeze, 7)));
  rig.run(2.0);
  EstimateReport e = rig.last_estimate();
  EXPECT_TRUE(e.frozen);
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.14);
  ASSERT_TRUE(rig.commands.push(command(Command::Kind::kSetValues, 8, 1.0, 2.5)));
  rig.run(0.2);
  e = rig.last_estimate();
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.0);
  EXPECT_DOUBLE_EQ(e.r_s_Ohm, 2.5);
  Command reconfigure;
  reconfigure.kind = Command::Kind::kReconfigure;
  reconfigure.live = rig.config.live;
  reconfigure.live.machine.estimator.algorithm = core::Algorithm::kGna;
  ASSERT_TRUE(rig.commands.push(reconfigure));
  ASSERT_TRUE(rig.commands.push(command(Command::Kind::kUnfreeze, 9)));
  rig.run(6.0);
  e = rig.last_estimate();
  EXPECT_EQ(e.algorithm, core::Algorithm::kGna);
  EXPECT_FALSE(e.frozen);
  EXPECT_NEAR(e.psi_m_Wb / (0.9 * 1.14), 1.0, 3e-3);  // the state carried over the reload
  ASSERT_TRUE(rig.commands.push(command(Command::Kind::kReset, 10)));
  rig.idle(0.2);
  e = rig.last_estimate();
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.14);
  // The statistics count what was applied, in sequence order.
  rig.idle(1.1);
  const LoopStatsReport stats = rig.last_stats();
  EXPECT_EQ(stats.rows.get(&diagnostics_t::commands_applied), 4);
  EXPECT_EQ(stats.rows.get(&diagnostics_t::command_sequence_errors), 0);
  EXPECT_EQ(stats.rows.get(&diagnostics_t::config_reloads), 1);
}

TEST(EstimatorLoop, GapsResynchroniseAndNonFiniteSamplesAreCounted) {
  Rig rig;
  rig.gen.n_pu = 0.4;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.2);
  rig.run(0.5);
  core::DriveSample s = rig.gen.next_si(rig.base, rig.t_ns);
  s.gap_before = true;
  ASSERT_TRUE(rig.input.push(s));
  core::DriveSample bad = rig.gen.next_si(rig.base, rig.t_ns);
  bad.i_A[1] = std::nan("");
  ASSERT_TRUE(rig.input.push(bad));
  rig.run(1.2);
  const LoopStatsReport stats = rig.last_stats();
  EXPECT_EQ(stats.rows.get(&diagnostics_t::resyncs), 3);  // the first sample, the gap, the sample after the rejected one
  EXPECT_EQ(stats.rows.get(&diagnostics_t::rejected_non_finite), 1);
  EXPECT_LT(stats.rows.get(&diagnostics_t::epsilon_rms_d_A), 1e-3);
  EXPECT_GE(stats.rows.get(&diagnostics_t::epsilon_rms_d_A), 0.0);
}

// A phase sample beyond what the machine produces (a current of 11·I_b: a wrong scale) is counted, not estimated on,
// and the sample after it resynchronises, as after a non-finite one (core::within).
TEST(EstimatorLoop, ASampleBeyondWhatTheMachineProducesIsCountedAndNotEstimatedOn) {
  Rig rig;
  rig.gen.n_pu = 0.4;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.2);
  rig.run(0.5);
  core::DriveSample bad = rig.gen.next_si(rig.base, rig.t_ns);
  bad.i_A[0] = 11.0 * rig.base.current_A;
  ASSERT_TRUE(rig.input.push(bad));
  rig.run(1.2);
  const LoopStatsReport stats = rig.last_stats();
  EXPECT_EQ(stats.rows.get(&diagnostics_t::rejected_implausible), 1);
  EXPECT_EQ(stats.rows.get(&diagnostics_t::rejected_non_finite), 0);
  EXPECT_EQ(stats.rows.get(&diagnostics_t::resyncs), 2);  // the first sample, the sample after the one left out
  EXPECT_LT(stats.rows.get(&diagnostics_t::epsilon_rms_d_A), 1e-3);
}

}  // namespace
}  // namespace rpem::daemon
