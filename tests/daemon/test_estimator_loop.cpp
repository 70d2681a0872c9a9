// The estimator loop's period work (process()) without threads: samples in, reports out; stale
// detection; commands; validity; derived temperatures.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/daemon/estimator_loop.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"

namespace rpem::daemon {
namespace {

struct Rig {
  DaemonConfig config = builtin_daemon_config();
  SpscQueue<core::DriveSample> input{16384};
  SpscQueue<Command> commands{16};
  SpscQueue<Report> output{65536};
  std::unique_ptr<EstimatorLoop> loop;
  test::ModelDataGenerator gen;
  core::PerUnitBase base = test::paper_base();
  std::int64_t t_ns = 0;
  std::int64_t now_ns = 1'000'000'000;

  Rig() {
    loop = std::make_unique<EstimatorLoop>(config, input, commands, output);
    gen.plant = test::paper_machine_pu();
    gen.omega_n_rad_s = base.omega_el_rad_s;
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
  EstimateReport last_estimate() {
    EstimateReport last;
    Report r;
    while (output.pop(r)) {
      if (auto* e = std::get_if<EstimateReport>(&r)) last = *e;
    }
    return last;
  }
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
  EXPECT_FALSE(stale.psi_m_valid);
  rig.run(0.5);
  EXPECT_EQ(rig.last_estimate().state, DaemonState::kRunning);
}

TEST(EstimatorLoop, CommandsFreezeSetResetAndReconfigure) {
  Rig rig;
  rig.gen.plant.psi_m_pu *= 0.9;
  rig.gen.n_pu = 0.4;
  rig.gen.i_ref_pu = core::mtpa_reference(rig.gen.plant, 0.3);
  Command freeze;
  freeze.kind = Command::Kind::kFreeze;
  freeze.seq = 7;
  ASSERT_TRUE(rig.commands.push(freeze));
  rig.run(2.0);
  EstimateReport e = rig.last_estimate();
  EXPECT_TRUE(e.frozen);
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.14);
  Command set;
  set.kind = Command::Kind::kSetValues;
  set.seq = 8;
  set.psi_m_Wb = 1.0;
  set.r_s_Ohm = 2.5;
  ASSERT_TRUE(rig.commands.push(set));
  rig.run(0.2);
  e = rig.last_estimate();
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.0);
  EXPECT_DOUBLE_EQ(e.r_s_Ohm, 2.5);
  Command reconfigure;
  reconfigure.kind = Command::Kind::kReconfigure;
  reconfigure.machine = rig.config.machine.machine;
  reconfigure.settings = rig.config.machine.estimator;
  reconfigure.settings.algorithm = core::Algorithm::kGna;
  reconfigure.temperature = rig.config.temperature;
  reconfigure.validity = rig.config.validity;
  Command unfreeze;
  unfreeze.kind = Command::Kind::kUnfreeze;
  unfreeze.seq = 9;
  ASSERT_TRUE(rig.commands.push(reconfigure));
  ASSERT_TRUE(rig.commands.push(unfreeze));
  rig.run(6.0);
  e = rig.last_estimate();
  EXPECT_EQ(e.algorithm, core::Algorithm::kGna);
  EXPECT_FALSE(e.frozen);
  EXPECT_NEAR(e.psi_m_Wb / (0.9 * 1.14), 1.0, 3e-3);  // the state carried over the reload
  Command reset;
  reset.kind = Command::Kind::kReset;
  reset.seq = 10;
  ASSERT_TRUE(rig.commands.push(reset));
  rig.idle(0.2);
  e = rig.last_estimate();
  EXPECT_DOUBLE_EQ(e.psi_m_Wb, 1.14);
  // The statistics acknowledge the last command.
  Report r;
  LoopStatsReport stats;
  rig.idle(1.1);
  while (rig.output.pop(r)) {
    if (auto* s = std::get_if<LoopStatsReport>(&r)) stats = *s;
  }
  EXPECT_EQ(stats.last_command_seq, 10);
  EXPECT_EQ(stats.last_command_result, CommandResult::kApplied);
  EXPECT_EQ(stats.commands_applied, 4);
  EXPECT_EQ(stats.config_reloads, 1);
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
  Report r;
  LoopStatsReport stats;
  while (rig.output.pop(r)) {
    if (auto* st = std::get_if<LoopStatsReport>(&r)) stats = *st;
  }
  EXPECT_EQ(stats.resyncs, 3);  // the first sample, the gap, the sample after the rejected one
  EXPECT_EQ(stats.rejected_non_finite, 1);
  EXPECT_LT(stats.eps_rms_d_A, 1e-3);
}

}  // namespace
}  // namespace rpem::daemon
