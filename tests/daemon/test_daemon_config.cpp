#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <variant>

#include "rpem/daemon/daemon_config.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

TEST(DaemonConfig, BuiltInDefaultIsTheSimulatedPaperMachine) {
  const DaemonConfig c = builtin_daemon_config();
  ASSERT_TRUE(std::holds_alternative<SimSource::Options>(c.fixed.source));
  EXPECT_EQ(std::get<SimSource::Options>(c.fixed.source).scenario, "builtin:rpemd-demo");
  EXPECT_DOUBLE_EQ(c.live.machine.machine.psi_m_Wb, 1.14);
  EXPECT_DOUBLE_EQ(c.fixed.loop.period_s, 125e-6);
  EXPECT_FALSE(c.live.commands_enabled);
  EXPECT_DOUBLE_EQ(c.live.temperature.r_s.value_ref, 2.25);
  EXPECT_DOUBLE_EQ(c.live.validity.max_hold_s, 20.0);
}

TEST(DaemonConfig, ShippedExamplesLoad) {
  for (const char* f : {"/config/rpemd-sim.yaml", "/config/rpemd-can.yaml", "/config/paper-ipmsm.yaml"}) {
    SCOPED_TRACE(f);
    const DaemonConfig c = load_daemon_config(test::source_dir() + f);
    EXPECT_GT(c.fixed.loop.period_s, 0.0);
  }
  const DaemonConfig can = load_daemon_config(test::source_dir() + "/config/rpemd-can.yaml");
  ASSERT_TRUE(std::holds_alternative<CanSource::Options>(can.fixed.source));
  EXPECT_EQ(std::get<CanSource::Options>(can.fixed.source).interface, "can0");
}

// The simulated drive runs the scenario the configuration checked: read once, so an edit between the check
// and the start (here the file made unreadable as a scenario) does not reach the loop.
TEST(DaemonConfig, TheSimulatedDriveRunsTheScenarioItsConfigurationChecked) {
  const test::TempFile scenario("checked-scenario.yaml", test::read_file(test::source_dir() + "/scenarios/rpemd-demo.yaml"));
  const test::TempFile config("rpemd-checked-scenario.yaml",
                              "daemon:\n  source: {type: sim, sim: {scenario: " + scenario.path() + ", loop: false}}\n");
  const DaemonConfig c = load_daemon_config(config.path());
  std::ofstream(scenario.path()) << "name: [not, a, scenario\n";
  const auto source = SourceCatalogue::make(c.fixed.source);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->name(), "rpemd-demo");
}

TEST(DaemonConfig, WakeAheadIsOffANumberOrAuto) {
  EXPECT_DOUBLE_EQ(builtin_daemon_config().fixed.loop.wake_ahead_s, 0.0);
  EXPECT_FALSE(builtin_daemon_config().fixed.loop.wake_ahead_auto);
  const test::TempFile number("wake_number.yaml", "daemon:\n  loop: {period_s: 125.0e-6, wake_ahead_s: 40.0e-6}\n");
  const DaemonConfig n = load_daemon_config(number.path());
  EXPECT_DOUBLE_EQ(n.fixed.loop.wake_ahead_s, 40e-6);
  EXPECT_FALSE(n.fixed.loop.wake_ahead_auto);
  const test::TempFile automatic("wake_auto.yaml", "daemon:\n  loop: {wake_ahead_s: auto}\n");
  EXPECT_TRUE(load_daemon_config(automatic.path()).fixed.loop.wake_ahead_auto);
}

TEST(DaemonConfig, AMachineFileAloneIsAConfiguration) {
  // rpem diagnose's extended.yaml is a machine file: rpemd must take it as it is.
  const DaemonConfig c = load_daemon_config(test::source_dir() + "/config/paper-ipmsm.yaml");
  EXPECT_TRUE(std::holds_alternative<SimSource::Options>(c.fixed.source));
  EXPECT_DOUBLE_EQ(c.live.machine.machine.l_q_H, 0.206);
}

TEST(DaemonConfig, DriftsFoundByDiagnoseCalibrateTheTemperatureModel) {
  // extended.yaml with drifts against temperature: rpemd derives temperatures with them, unless its own
  // daemon.temperature section says otherwise.
  const std::string machine = test::read_file(test::source_dir() + "/config/paper-ipmsm.yaml") +
                              "model_extensions:\n"
                              "  rs_drift: {coeff_per_K: 0.0041, reference_C: 25, r_s_ref_Ohm: 2.3}\n"
                              "  psim_drift: {coeff_per_K: -0.00105, reference_C: 25}\n";
  test::TempFile f("ext.yaml", machine);
  const DaemonConfig c = load_daemon_config(f.path());
  EXPECT_DOUBLE_EQ(c.live.temperature.r_s.reference_C, 25.0);
  EXPECT_DOUBLE_EQ(c.live.temperature.psi_m.reference_C, 25.0);
  EXPECT_DOUBLE_EQ(c.live.temperature.r_s.coeff_per_K, 0.0041);
  EXPECT_DOUBLE_EQ(c.live.temperature.r_s.value_ref, 2.3);
  EXPECT_DOUBLE_EQ(c.live.temperature.psi_m.coeff_per_K, -0.00105);
  EXPECT_DOUBLE_EQ(c.live.temperature.psi_m.value_ref, 1.14);  // not found: the machine's
  test::TempFile g("own.yaml", machine + "daemon:\n  temperature: {r_s_coeff_per_K: 0.00393}\n");
  EXPECT_DOUBLE_EQ(load_daemon_config(g.path()).live.temperature.r_s.coeff_per_K, 0.00393);
  test::TempFile h("bad.yaml", test::read_file(test::source_dir() + "/config/paper-ipmsm.yaml") +
                                   "model_extensions:\n  psim_drift: {coeff_per_K: 0.001}\n");
  EXPECT_THROW((void)load_daemon_config(h.path()), io::ConfigError);
}

TEST(DaemonConfig, AThermalSectionInlineOrInItsOwnFileRunsTheFusion) {
  EXPECT_FALSE(builtin_daemon_config().live.thermal_active);
  const std::string section =
      "thermal:\n"
      "  nodes:\n"
      "    - {name: winding, capacitance_J_per_K: 3000, to_coolant_W_per_K: 2}\n"
      "    - {name: magnet, capacitance_J_per_K: 7000, to_coolant_W_per_K: 4}\n"
      "  conductances: [{from: winding, to: magnet, W_per_K: 12}]\n"
      "  coolant_C: 35\n";
  const std::string machine = test::read_file(test::source_dir() + "/config/paper-ipmsm.yaml");
  test::TempFile inline_file("thermal_inline.yaml", machine + section);
  const DaemonConfig c = load_daemon_config(inline_file.path());
  ASSERT_TRUE(c.live.thermal_active);
  EXPECT_EQ(c.live.thermal.filter.network.nodes, 2);
  EXPECT_DOUBLE_EQ(c.live.thermal.filter.network.between_W_per_K(0, 1), 12.0);
  EXPECT_DOUBLE_EQ(c.live.thermal.coolant_C, 35.0);
  // The section states neither law, and the paper machine no drift: rpemd says both assumptions at start, as rpem
  // estimate does (io::assumed_law_notes, tested with the reader); and no node a process noise or a disturbance
  // (io::process_noise_note).
  ASSERT_EQ(c.notes.size(), 3U);
  EXPECT_NE(c.notes[0].find("the copper law takes r_s_ref"), std::string::npos) << c.notes[0];
  EXPECT_NE(c.notes[1].find("the magnet law takes psi_m_ref 1.14 Wb at 20 °C"), std::string::npos) << c.notes[1];
  EXPECT_NE(c.notes[2].find("no node states process_noise_K2_per_s"), std::string::npos) << c.notes[2];
  EXPECT_TRUE(builtin_daemon_config().notes.empty());
  // The file `rpem thermal fit` wrote, named relative to the configuration.
  test::TempFile own("thermal_own.yaml", section);
  test::TempFile named("thermal_named.yaml", machine + "daemon:\n  thermal_config: " +
                                                 std::filesystem::path(own.path()).filename().string() + "\n");
  const DaemonConfig d = load_daemon_config(named.path());
  ASSERT_TRUE(d.live.thermal_active);
  EXPECT_DOUBLE_EQ(d.live.thermal.filter.network.capacitance_J_per_K[1], 7000.0);
  EXPECT_EQ(d.notes, c.notes);
  // Both: an error naming the key; a bad section: the thermal section's own error.
  test::TempFile both("thermal_both.yaml", machine + section + "daemon:\n  thermal_config: x.yaml\n");
  EXPECT_THROW((void)load_daemon_config(both.path()), io::ConfigError);
  test::TempFile bad("thermal_bad.yaml", machine + "thermal:\n  nodes: [{name: winding, capacitance_J_per_K: -1}]\n");
  EXPECT_THROW((void)load_daemon_config(bad.path()), io::ConfigError);
}

TEST(DaemonConfig, SourcesComeFromTheCatalogueAndOnlyTheChosenOneIsKept) {
  const test::TempFile f(
      "both.yaml",
      "daemon:\n  source: {type: can, can: {interface: vcan3}, sim: {scenario: builtin:rpemd-demo, loop: false}}\n");
  const DaemonConfig c = load_daemon_config(f.path());
  ASSERT_TRUE(std::holds_alternative<CanSource::Options>(c.fixed.source));
  EXPECT_EQ(std::get<CanSource::Options>(c.fixed.source).interface, "vcan3");
  EXPECT_STREQ(SourceCatalogue::type(c.fixed.source), "can");
  EXPECT_STREQ(SourceCatalogue::type(builtin_daemon_config().fixed.source), "sim");
}

// A VESC source sets how often samples come: a reply every poll period T, up to reply_timeout_s after its poll. The
// stale timeout's default outlasts one lost reply (2·T + timeout) and never falls below the loop's own 0.1 s.
TEST(DaemonConfig, AVescSourcesStaleTimeoutOutlastsOneLostReply) {
  const auto stale_s = [](const std::string& vesc, const std::string& rest = "") {
    const test::TempFile f(
        "vesc.yaml", "daemon:\n  source: {type: vesc, vesc: {interface: vcan0, controller_id: 17, " + vesc + "}}\n" + rest);
    return load_daemon_config(f.path()).fixed.loop.stale_timeout_s;
  };
  EXPECT_NEAR(stale_s("poll_rate_Hz: 10"), 2 * 0.1 + 0.02, 1e-12);  // the default timeout: 20 ms at most
  EXPECT_NEAR(stale_s("poll_rate_Hz: 1, reply_timeout_s: 0.5"), 2 * 1.0 + 0.5, 1e-12);
  EXPECT_EQ(stale_s("poll_rate_Hz: 200"), 0.1);  // 2·5 ms + 4.5 ms is less than the loop's default
  EXPECT_EQ(stale_s("poll_rate_Hz: 10", "  stale_timeout_s: 0.15\n"), 0.15);  // stale on one lost reply: allowed
  EXPECT_EQ(
      load_daemon_config(test::TempFile("can.yaml", "daemon:\n  source: {type: can, can: {interface: vcan0}}\n").path())
          .fixed.loop.stale_timeout_s,
      0.1);  // the drive pushes: nothing to go by
}

TEST(DaemonConfig, FixedDifferenceNamesWhatOnlyARestartApplies) {
  const DaemonConfig a = builtin_daemon_config();
  DaemonConfig b = a;
  EXPECT_STREQ(fixed_difference(a.fixed, b.fixed), "");
  b.live.machine.estimator.algorithm = core::Algorithm::kGna;  // live: a reload applies it
  b.live.commands_enabled = true;
  EXPECT_STREQ(fixed_difference(a.fixed, b.fixed), "");
  b.fixed.lcm.channel_prefix = "X_";
  EXPECT_STREQ(fixed_difference(a.fixed, b.fixed), "lcm");
  b = a;
  b.fixed.source = CanSource::Options{"can1"};
  EXPECT_STREQ(fixed_difference(a.fixed, b.fixed), "source");
  b = a;
  b.fixed.loop.thread.cpu = 1;
  EXPECT_STREQ(fixed_difference(a.fixed, b.fixed), "loop");
  b = a;
  b.fixed.publish_thread.priority = 3;
  EXPECT_STREQ(fixed_difference(a.fixed, b.fixed), "threads");
}

struct Bad {
  const char* name;
  const char* text;
  const char* expected;
};
class BadDaemonConfig : public ::testing::TestWithParam<Bad> {};

TEST_P(BadDaemonConfig, IsRejectedWithFileLineAndField) {
  test::TempFile f("rpemd.yaml", std::string(GetParam().text));
  try {
    (void)load_daemon_config(f.path());
    FAIL() << "accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(GetParam().expected), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadDaemonConfig,
    ::testing::Values(Bad{"unknown", "daemon: {sauce: {type: can}}\n", ":1:10: daemon.sauce: unknown key"},
                      Bad{"source_type", "daemon:\n  source: {type: serial}\n",
                          "daemon.source.type: 'serial' is not one of: sim, can"},
                      Bad{"priority", "daemon:\n  loop: {thread: {policy: fifo, priority: 120}}\n",
                          "daemon.loop.thread.priority: 120 is outside [1, 99]"},
                      Bad{"period", "daemon:\n  loop: {period_s: 5}\n", "daemon.loop.period_s: 5 is outside"},
                      Bad{"wake_ahead", "daemon:\n  loop: {period_s: 1.0e-3, wake_ahead_s: 6.0e-4}\n",
                          "daemon.loop.wake_ahead_s: 6.0e-4 is outside [0, 0.0005]"},
                      Bad{"both_machines", "daemon: {machine_config: a.yaml}\nmachine: {}\n",
                          "give the machine inline or daemon.machine_config"},
                      Bad{"iface", "daemon:\n  source: {type: can, can: {interface: ''}}\n", "not an interface name"},
                      Bad{"coefficient_sign", "daemon:\n  temperature: {psi_m_coeff_per_K: 0.001}\n",
                          "psi_m_coeff_per_K: 0.001 is outside"},
                      Bad{"stale_between_polls",
                          "daemon:\n  source: {type: vesc, vesc: {interface: vcan0, controller_id: 17, poll_rate_Hz: 10}}\n"
                          "  stale_timeout_s: 0.1\n",
                          ":3:20: daemon.stale_timeout_s: 0.1 s is within the 0.12 s the vesc source's samples may "
                          "come apart (one poll period and reply_timeout_s): rpemd would go stale, and start over, "
                          "between two of them; leave it out (then 0.22 s"}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace rpem::daemon
