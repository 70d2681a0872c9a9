// Scenario files: the shipped ones load; mistakes are named with file:line.
#include <gtest/gtest.h>

#include <filesystem>

#include "rpem/sim/scenario.hpp"
#include "support/temp_file.hpp"

namespace rpem::sim {
namespace {

TEST(Scenario, EveryShippedScenarioLoads) {
  int count = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::source_dir() + "/scenarios")) {
    if (e.path().extension() != ".yaml") continue;
    SCOPED_TRACE(e.path().string());
    const Scenario s = load_scenario(e.path().string());
    EXPECT_GT(s.duration_s, 0.0);
    ++count;
  }
  EXPECT_GT(count, 0);
}

TEST(Scenario, EventsAndDefaults) {
  const Scenario s = parse_scenario(
      "duration_s: 3\ninitial: {speed_rpm: 300, torque_Nm: 5}\n"
      "events:\n  - {t_s: 1, quantity: psi_m_Wb, kind: step, scale: 0.92}\n"
      "  - {t_s: 2, quantity: speed_rpm, kind: ramp, value: -300, duration_s: 0.5}\n",
      "s.yaml", "");
  EXPECT_EQ(s.machine.machine.rated.pole_pairs, 3);
  EXPECT_DOUBLE_EQ(s.signal(Quantity::kPsiM).events()[0].target, 0.92 * 1.14);
  EXPECT_DOUBLE_EQ(s.signal(Quantity::kSpeed).initial(), 300.0);
  EXPECT_EQ(s.inverter.model, InverterModel::kSwitching);
  EXPECT_EQ(s.integrator, PlantIntegrator::kEdges);
  const Scenario fixed = parse_scenario("duration_s: 1\nplant: {integrator: fixed}\n", "f.yaml", "");
  EXPECT_EQ(fixed.integrator, PlantIntegrator::kFixedStep);
  EXPECT_DOUBLE_EQ(fixed.plant_step_s, 1e-6);
  const Scenario averaged = parse_scenario("duration_s: 1\ninverter: {model: averaged}\n", "a.yaml", "");
  EXPECT_EQ(averaged.integrator, PlantIntegrator::kFixedStep);
  EXPECT_DOUBLE_EQ(averaged.plant_step_s, averaged.sample_period_s);
}

struct Bad {
  const char* name;
  const char* text;
  const char* expected;
};
class BadScenario : public ::testing::TestWithParam<Bad> {};

TEST(Scenario, RegimesLoadAndSetTheirDefaults) {
  const Scenario s = parse_scenario(
      "duration_s: 3\nplant: {mechanics: {mode: inertia}}\ninitial: {load_torque_Nm: 0.2}\n"
      "regimes:\n  - {t_s: 0.5, regime: open_loop, current_A: 20, speed_rpm: -300, ramp_s: 1, control: speed}\n"
      "  - {t_s: 2, regime: bridge_off, report: zero}\n"
      "  - {t_s: 2.5, regime: open_loop, current_A: 9, speed_rpm: 100, ramp_s: 0.2, lock_s: 0.1, hold_s: 0, then: bridge_off}\n",
      "r.yaml", "");
  EXPECT_TRUE(s.separate_load);
  ASSERT_EQ(s.regimes.size(), 3U);
  const RegimeEvent& a = s.regimes[0];
  EXPECT_EQ(a.regime, DriveRegime::kOpenLoop);
  EXPECT_EQ(a.then, DriveRegime::kClosedLoop);
  EXPECT_EQ(a.control, ControlOverride::kSpeed);
  EXPECT_DOUBLE_EQ(a.speed_rpm, -300.0);
  EXPECT_DOUBLE_EQ(a.lock_s, 0.0);
  EXPECT_DOUBLE_EQ(a.hold_s, 0.05);  // VESC's foc_sl_openloop_time default
  EXPECT_EQ(s.regimes[1].report, OffVoltageReport::kZero);
  EXPECT_EQ(s.regimes[2].then, DriveRegime::kBridgeOff);
  EXPECT_EQ(s.regimes[2].report, OffVoltageReport::kBackEmf);
  RegimeTimeline timeline(s.regimes);
  EXPECT_EQ(timeline.at(0.4).regime, DriveRegime::kClosedLoop);
  EXPECT_EQ(timeline.at(0.5).regime, DriveRegime::kOpenLoop);
  EXPECT_DOUBLE_EQ(timeline.at(1.0).open_loop_speed_rpm, -150.0);  // half-way up the ramp
  EXPECT_DOUBLE_EQ(timeline.at(1.52).open_loop_speed_rpm, -300.0);
  EXPECT_EQ(timeline.at(1.56).regime, DriveRegime::kClosedLoop);  // after 0 + 1 + 0.05 s: the observer
  EXPECT_EQ(timeline.at(2.0).regime, DriveRegime::kBridgeOff);
  EXPECT_DOUBLE_EQ(timeline.at(2.55).open_loop_speed_rpm, 0.0);  // locked
  EXPECT_EQ(timeline.at(2.81).regime, DriveRegime::kBridgeOff);  // released after 0.1 + 0.2 + 0 s
}

TEST_P(BadScenario, IsRejectedWithLine) {
  try {
    (void)parse_scenario(GetParam().text, "bad.yaml", "");
    FAIL() << "accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(GetParam().expected), std::string::npos) << e.what();
  }
}

TEST(Scenario, ADirectoryIsRefusedByName) {
  try {
    (void)load_scenario("/");
    FAIL() << "accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/: is a directory, not a file"), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadScenario,
    ::testing::Values(
        Bad{"unknown", "duration_s: 1\nspeed: 3\n", "bad.yaml:2:1: speed: unknown key"},
        Bad{"quantity", "duration_s: 1\nevents:\n  - {t_s: 1, quantity: flux, kind: step, value: 1}\n",
            "bad.yaml:3:24: events[0].quantity: 'flux' is not one of"},
        Bad{"both", "duration_s: 1\nevents:\n  - {t_s: 1, quantity: r_s_Ohm, kind: step, value: 1, scale: 2}\n",
            "give exactly one of value and scale"},
        Bad{"order",
            "duration_s: 1\nevents:\n  - {t_s: 2, quantity: r_s_Ohm, kind: step, value: 1}\n"
            "  - {t_s: 1, quantity: r_s_Ohm, kind: step, value: 2}\n",
            "events[1].t_s: events of one quantity must be in time order"},
        Bad{"speed_on_dyno", "duration_s: 1\ncontrol: {mode: speed}\n", "speed control needs plant.mechanics.mode: inertia"},
        Bad{"step", "duration_s: 1\nplant: {integrator: fixed, step_s: 3.0e-6}\n", "step_s must divide sample_period_s"},
        Bad{"step_with_edges", "duration_s: 1\nplant: {step_s: 1.0e-6}\n", "plant.step_s: applies to integrator: fixed"},
        Bad{"edges_averaged", "duration_s: 1\ninverter: {model: averaged}\nplant: {integrator: edges}\n",
            "plant.integrator: edges needs inverter.model: switching"},
        Bad{"machine", "duration_s: 1\nmachine: nowhere.yaml\n", "nowhere.yaml: cannot open file"},
        Bad{"regime_order", "duration_s: 1\nregimes:\n  - {t_s: 1, regime: bridge_off}\n  - {t_s: 1, regime: closed_loop}\n",
            "bad.yaml:4:11: regimes[1].t_s: regime events must be in strictly increasing time"},
        Bad{"regime_name", "duration_s: 1\nregimes:\n  - {t_s: 1, regime: coasting}\n",
            "bad.yaml:3:22: regimes[0].regime: 'coasting' is not one of: closed_loop, open_loop, bridge_off"},
        Bad{"open_loop_current", "duration_s: 1\nregimes:\n  - {t_s: 1, regime: open_loop, speed_rpm: 300, ramp_s: 1}\n",
            "regimes[0].current_A: required key is missing"},
        Bad{"open_loop_direction",
            "duration_s: 1\nregimes:\n  - {t_s: 1, regime: open_loop, current_A: 5, speed_rpm: 0, ramp_s: 1}\n",
            "regimes[0].speed_rpm: must not be 0"},
        Bad{"released_with_control",
            "duration_s: 1\nregimes:\n  - {t_s: 1, regime: open_loop, current_A: 5, speed_rpm: 9, ramp_s: 1, then: bridge_off, "
            "control: torque}\n",
            "regimes[0].control: unknown key"},
        Bad{"regime_speed_on_dyno", "duration_s: 1\nregimes:\n  - {t_s: 1, regime: closed_loop, control: speed}\n",
            "regimes[0].control: speed control needs plant.mechanics.mode: inertia"},
        Bad{"report", "duration_s: 1\nregimes:\n  - {t_s: 1, regime: bridge_off, report: none}\n",
            "regimes[0].report: 'none' is not one of: back_emf, zero"},
        Bad{"load_on_dyno", "duration_s: 1\ninitial: {load_torque_Nm: 1}\n",
            "bad.yaml:2:27: initial.load_torque_Nm: needs plant.mechanics.mode: inertia"},
        Bad{"load_event_on_dyno", "duration_s: 1\nevents:\n  - {t_s: 1, quantity: load_torque_Nm, kind: step, value: 1}\n",
            "events[0].quantity: load_torque_Nm needs plant.mechanics.mode: inertia"},
        Bad{"thermal_plant_event",
            "duration_s: 1\nthermal_plant: {coolant_C: 25, winding_J_K: 1, iron_J_K: 1, magnet_J_K: 1, "
            "winding_iron_W_K: 1, iron_coolant_W_K: 1, gap_W_K: 1, magnet_coolant_W_K: 0, hysteresis_W: 0, eddy_W: 0, "
            "magnet_eddy_W: 0}\nevents:\n  - {t_s: 1, quantity: t_winding_C, kind: thermal, value: 90, tau_s: 60}\n",
            "bad.yaml:4:24: events[0].quantity: the temperatures are thermal_plant's state"},
        Bad{"thermal_plant_initial",
            "duration_s: 1\nthermal_plant: {coolant_C: 25, winding_J_K: 1, iron_J_K: 1, magnet_J_K: 1, "
            "winding_iron_W_K: 1, iron_coolant_W_K: 1, gap_W_K: 1, magnet_coolant_W_K: 0, hysteresis_W: 0, eddy_W: 0, "
            "magnet_eddy_W: 0}\ninitial: {t_magnet_C: 60}\n",
            "initial.t_magnet_C: with thermal_plant the temperatures start at thermal_plant.start_C"},
        Bad{"thermal_plant_missing", "duration_s: 1\nthermal_plant: {coolant_C: 25}\n",
            "thermal_plant.winding_J_K: required key is missing"},
        Bad{"thermal_plant_negative",
            "duration_s: 1\nthermal_plant: {coolant_C: 25, winding_J_K: 1, iron_J_K: 1, magnet_J_K: 1, "
            "winding_iron_W_K: -1, iron_coolant_W_K: 1, gap_W_K: 1, magnet_coolant_W_K: 0, hysteresis_W: 0, eddy_W: 0, "
            "magnet_eddy_W: 0}\n",
            "thermal_plant.winding_iron_W_K"},
        Bad{"vesc_key", "duration_s: 1\nvesc: {wheel_mm: 3}\n", "bad.yaml:2:8: vesc.wheel_mm: unknown key"},
        // A directory opens and then fails to read: it escaped as std::ios_base::failure (fuzz_scenario).
        Bad{"machine_directory", "duration_s: 1\nmachine: /\n", "/: is a directory, not a file"}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace rpem::sim
