// The thermal fields of RPEM_ESTIMATE (docs/thermal.md, "In rpemd"): filled from the loop's fusion, NaN/0/−1
// without a network, and named as `rpem estimate --thermal` names its columns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <functional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "rpem/daemon/loop_thread.hpp"
#include "rpem/daemon/state_file.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/io/estimate_log.hpp"
#include "rpem/schema/text.hpp"
#include "support/loop_queues.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/paper_thermal.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

/// The drive's temperature sensors on a phase sample (the k-th of the run).
using Sensors = std::function<void(core::DriveSample&, int k)>;

/// Runs `seconds` of the model's phase samples at 8 kHz (n = 0.4 pu: ψm adapts) through a loop; the last estimate.
/// `before` sees the loop before it runs (as rpemd's start-up does); `sensors` gives the samples' temperatures.
EstimateReport run_loop(
    const DaemonConfig& config, int seconds, const std::function<void(LoopThread&)>& before = [](LoopThread&) {},
    const Sensors& sensors = [](core::DriveSample&, int) {}) {
  auto [input, commands, output, ends] = test::loop_queues(4096, 16, 1 << 12);
  LoopThread loop(config, std::move(ends));
  before(loop);
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.omega_n_rad_s = test::paper_base().omega_el_rad_s;
  gen.n_pu = 0.4;
  gen.i_ref_pu = core::mtpa_reference(gen.plant, 0.4);
  const core::PerUnitBase base = test::paper_base();
  std::int64_t t_ns = 0, now = 1'000'000'000;
  EstimateReport last;
  Report r;
  for (int period = 0; period < seconds * 1000; ++period) {
    for (int s = 0; s < 8; ++s) {
      core::DriveSample sample = gen.next_si(base, t_ns);
      sensors(sample, period * 8 + s);
      (void)input.push(sample);
    }
    now += 1'000'000;
    loop.process(now);
    while (output.pop(r)) {
      if (const auto* e = std::get_if<EstimateReport>(&r)) last = *e;
    }
  }
  return last;
}

/// The built-in configuration with the paper machine's network, its coolant at 40 °C.
DaemonConfig with_network() {
  DaemonConfig config = builtin_daemon_config();
  config.live.thermal = test::paper_thermal_fusion();
  config.live.thermal.coolant_C = 40.0;
  config.live.thermal_active = true;
  return config;
}

TEST(LoopThermal, WithoutANetworkTheFieldsSayNone) {
  const EstimateReport e = run_loop(builtin_daemon_config(), 2);
  EXPECT_FALSE(e.thermal_active);
  EXPECT_TRUE(std::isnan(e.t_magnet_fused_C));
  EXPECT_TRUE(std::isnan(e.t_winding_fused_sd_C));
  EXPECT_EQ(e.t_magnet_source, mirror::estimate_t::SOURCE_NONE);
  EXPECT_EQ(e.t_winding_source, mirror::estimate_t::SOURCE_NONE);
  EXPECT_EQ(e.t_magnet_observed_age_s, -1.0);
}

TEST(LoopThermal, WithANetworkTheFusedTemperaturesAreReported) {
  DaemonConfig config = with_network();
  const EstimateReport e = run_loop(config, 10);
  ASSERT_TRUE(e.thermal_active);
  // Ten seconds against time constants of minutes, from a soaked machine at the coolant: near 40 °C, and the
  // magnet observed through ψ̂m (the model's ψm is the law's value at 20 °C: the observations pull it down).
  EXPECT_TRUE(std::isfinite(e.t_magnet_fused_C));
  EXPECT_GT(e.t_magnet_fused_sd_C, 0.0);
  EXPECT_LT(e.t_magnet_fused_sd_C, test::paper_thermal_fusion().initial_sigma_K);
  EXPECT_GT(e.t_winding_fused_sd_C, 0.0);
  for (std::int8_t source : {e.t_magnet_source, e.t_winding_source}) {
    EXPECT_TRUE(source == mirror::estimate_t::SOURCE_OBSERVED || source == mirror::estimate_t::SOURCE_PREDICTED);
  }
  EXPECT_GE(e.t_magnet_observed_age_s, 0.0);  // observed at least once
  EXPECT_LT(e.t_magnet_observed_age_s, 10.0);
}

// A phase sample carries the drive's sensors (the native protocol's temperature frame, a signal map of phases, the
// simulated drive): its coolant is the network's boundary, held between readings (here one sample in 800: 10 Hz
// of an 8 kHz stream), as an averaged sample's is (AveragedLoop.TheDrivesCoolantSensorIsTheNetworksBoundaryAndHolds).
TEST(LoopThermal, APhaseSamplesCoolantReadingIsTheNetworksBoundary) {
  constexpr double kConfigured_C = 40.0, kMeasured_C = 22.5;
  ASSERT_EQ(with_network().live.thermal.coolant_C, kConfigured_C);
  const EstimateReport without = run_loop(with_network(), 3);
  ASSERT_TRUE(without.thermal_active);
  EXPECT_DOUBLE_EQ(without.thermal.load.coolant_C, kConfigured_C);
  const EstimateReport with = run_loop(
      with_network(), 3, [](LoopThread&) {},
      [](core::DriveSample& s, int k) {
        if (k % 800 == 0) s.t_coolant_C = kMeasured_C;
      });
  EXPECT_NEAR(with.thermal.load.coolant_C, kMeasured_C, 1e-9);
}

// A winding sensor configured (thermal.winding_sensor) but silent leaves the soaked start untested: the report says
// so (the publisher notes it once); with a reading in the first step, or without a sensor configured (rpemd says
// that at its start), it does not.
TEST(LoopThermal, AConfiguredWindingSensorThatGivesNoReadingLeavesTheSoakedStartUntested) {
  DaemonConfig config = with_network();
  config.live.thermal.winding_sensor_sigma_K = 1.0;
  const EstimateReport silent = run_loop(config, 2);
  ASSERT_TRUE(silent.thermal_active);
  EXPECT_TRUE(silent.thermal_start_untested_by_sensor);
  const EstimateReport read = run_loop(
      config, 2, [](LoopThread&) {},
      [](core::DriveSample& s, int k) {
        if (k % 800 == 0) s.t_winding_C = 40.0;
      });
  ASSERT_TRUE(read.thermal_active);
  EXPECT_FALSE(read.thermal_start_untested_by_sensor);
  DaemonConfig unsensed = with_network();
  unsensed.live.thermal.winding_sensor_sigma_K = 0.0;
  const EstimateReport without_sensor = run_loop(unsensed, 2);
  ASSERT_TRUE(without_sensor.thermal_active);
  EXPECT_FALSE(without_sensor.thermal_start_untested_by_sensor);
}

// A restart (docs/thermal.md, "A restart"): the state the loop reports goes through the state file and starts
// the next loop's fusion where it stands after the gap (core::across_unknown_load), not at the coolant. The
// second run makes no observation (its observer does not settle), so what it reports is the resumed state carried
// one second by the network.
TEST(LoopThermal, ARestartResumesTheReportedStateThroughTheStateFile) {
  DaemonConfig config = with_network();
  const EstimateReport first = run_loop(config, 10);
  const core::ThermalSnapshot& reported = first.thermal;
  ASSERT_EQ(reported.nodes, 3);
  EXPECT_EQ(reported.magnet, config.live.thermal.filter.network.magnet);
  EXPECT_EQ(reported.t_C[reported.magnet], first.t_magnet_fused_C);
  EXPECT_EQ(std::sqrt(reported.p_K2(reported.magnet, reported.magnet)), first.t_magnet_fused_sd_C);

  PersistedEstimates saved;  // the machine 50 K hotter than this run made it
  saved.written_unix_s = std::time(nullptr) - 20;
  saved.thermal = {reported, saved.written_unix_s};
  saved.thermal.state.t_C.head(3).array() += 50.0;
  const test::TempFile f("estimates.json");
  ASSERT_EQ(write_state_file(f.path(), saved), "");
  const LoadedState loaded = load_state_file(f.path(), 3600.0, 0.5, 1.7, 1.0, 4.5);
  ASSERT_EQ(loaded.status, StateFileStatus::kLoaded) << loaded.message;

  config.live.thermal.observer.settle_time_constants = 1e6;
  const double gap_s = 20.0;
  const core::ThermalSnapshot expected =
      core::across_unknown_load(config.live.thermal.filter, loaded.estimates.thermal.state, gap_s, 0.01);
  const EstimateReport resumed =
      run_loop(config, 1, [&](LoopThread& l) { ASSERT_TRUE(l.resume_thermal(loaded.estimates.thermal.state, gap_s)); });
  const int m = reported.magnet;
  // One second against the network's minutes: within 0.5 K of where the gap left it, far above the fresh start.
  EXPECT_NEAR(resumed.t_magnet_fused_C, expected.t_C[m], 0.5);
  EXPECT_GT(resumed.t_magnet_fused_sd_C, 0.0);
  const EstimateReport fresh = run_loop(config, 1);
  EXPECT_NEAR(fresh.t_magnet_fused_C, 40.0, 0.5);
  EXPECT_GT(resumed.t_magnet_fused_C - fresh.t_magnet_fused_C, 25.0);  // half the 50 K, after 20 s of cooling

  // Another network, or none: not resumed.
  core::ThermalSnapshot other = loaded.estimates.thermal.state;
  other.nodes = 2;
  (void)run_loop(config, 0, [&](LoopThread& l) { EXPECT_FALSE(l.resume_thermal(other, gap_s)); });
  config.live.thermal_active = false;
  (void)run_loop(config, 0, [&](LoopThread& l) { EXPECT_FALSE(l.resume_thermal(loaded.estimates.thermal.state, gap_s)); });
}

TEST(LoopThermal, TheEstimateCsvNamesTheColumnsAsRpemListensCsv) {
  const std::string listen = schema::csv_header<rpem::estimate_t>();
  const test::TempFile f("est.csv");
  { io::EstimateLogWriter w(f.path(), {"winding", "magnet"}); }
  const std::string estimate = test::read_file(f.path());
  auto columns = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream s(line.substr(0, line.find('\n')));
    for (std::string c; std::getline(s, c, ',');) out.push_back(c);
    return out;
  };
  const std::vector<std::string> l = columns(listen), est = columns(estimate);
  for (const char* node : {"magnet", "winding"}) {
    const std::string n(node);
    for (const std::string& c :
         {"t_" + n + "_fused_C", "t_" + n + "_fused_sd_C", "t_" + n + "_source", "t_" + n + "_observed_age_s"}) {
      SCOPED_TRACE(c);
      EXPECT_NE(std::find(l.begin(), l.end(), c), l.end());
      EXPECT_NE(std::find(est.begin(), est.end(), c), est.end());
    }
  }
}

}  // namespace
}  // namespace rpem::daemon
