// What the publisher persists of the thermal fusion (docs/thermal.md, "A restart"): the fusion's newest state at
// its report's time; before the fusion reports one, the state a restart resumed, with its own time — so a restart
// while no sample arrives does not lose it for the next.
#include <gtest/gtest.h>

#include <atomic>
#include <ctime>
#include <utility>

#include "rpem/daemon/publisher.hpp"
#include "rpem/daemon/spsc_queue.hpp"
#include "rpem/daemon/state_file.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

core::ThermalSnapshot two_node_state(double magnet_C) {
  core::ThermalSnapshot t;
  t.nodes = 2, t.winding = 0, t.magnet = 1;
  t.t_C << magnet_C + 10.0, magnet_C, 0.0, 0.0;
  t.p_K2.diagonal() << 4.0, 9.0, 0.0, 0.0;
  t.load.coolant_C = 40.0;
  return t;
}

/// The state file a publisher writes at its end, given what it resumed and one estimate report.
PersistedEstimates written(const std::string& path, const PersistedThermal& resumed, const EstimateReport& report) {
  FixedConfig config;
  config.state.file = path;
  config.lcm.url = "memq://";  // in-process: nothing on the network
  config.loop.realtime = RealtimeMode::kOff;
  auto loop = SpscQueue<Report>::make(4);
  auto source = SpscQueue<SourceReport>::make(4);
  auto control = SpscQueue<ControlReport>::make(4);
  {
    PersistingPublisher publisher(config, {"sim", "test", StateFileStatus::kLoaded, resumed},
                                  {std::move(loop.consumer), std::move(source.consumer), std::move(control.consumer)});
    EXPECT_TRUE(loop.producer.push(report));
    const std::atomic<bool> stop{true};
    publisher.run(stop);  // drains, then writes the state file a last time
  }
  const LoadedState s = load_state_file(path, 3600.0, 0.5, 1.7, 1.0, 4.5);
  EXPECT_EQ(s.status, StateFileStatus::kLoaded) << s.message;
  return s.estimates;
}

TEST(PublisherState, AResumedThermalStateIsKeptUntilTheFusionReportsItsOwn) {
  const test::TempFile f("estimates.json");
  const std::int64_t now_s = std::time(nullptr);
  const PersistedThermal resumed{two_node_state(90.0), now_s - 100};
  EstimateReport r;  // estimates, but the fusion has not stepped (no sample since the restart)
  r.utime = now_s * 1'000'000;
  r.has_good_r_s = true;
  r.good_r_s_Ohm = 2.4;
  const PersistedEstimates kept = written(f.path(), resumed, r);
  EXPECT_EQ(kept.thermal.state.t_C, resumed.state.t_C);
  EXPECT_EQ(kept.thermal.at_unix_s, now_s - 100);  // its own time: the next restart's gap counts from it

  r.thermal = two_node_state(60.0);  // the fusion's own
  r.utime = (now_s - 2) * 1'000'000;
  const PersistedEstimates own = written(f.path(), resumed, r);
  EXPECT_EQ(own.thermal.state.t_C, r.thermal.t_C);
  EXPECT_EQ(own.thermal.at_unix_s, now_s - 2);

  // Nothing resumed and no network: no thermal state written.
  r.thermal = core::ThermalSnapshot{};
  EXPECT_EQ(written(f.path(), PersistedThermal{}, r).thermal.state.nodes, 0);
}

}  // namespace
}  // namespace rpem::daemon
