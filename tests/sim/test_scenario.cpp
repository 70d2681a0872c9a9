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
        Bad{"order", "duration_s: 1\nevents:\n  - {t_s: 2, quantity: r_s_Ohm, kind: step, value: 1}\n"
                     "  - {t_s: 1, quantity: r_s_Ohm, kind: step, value: 2}\n",
            "events[1].t_s: events of one quantity must be in time order"},
        Bad{"speed_on_dyno", "duration_s: 1\ncontrol: {mode: speed}\n", "speed control needs plant.mechanics.mode: inertia"},
        Bad{"step", "duration_s: 1\nplant: {integrator: fixed, step_s: 3.0e-6}\n", "step_s must divide sample_period_s"},
        Bad{"step_with_edges", "duration_s: 1\nplant: {step_s: 1.0e-6}\n", "plant.step_s: applies to integrator: fixed"},
        Bad{"edges_averaged", "duration_s: 1\ninverter: {model: averaged}\nplant: {integrator: edges}\n",
            "plant.integrator: edges needs inverter.model: switching"},
        Bad{"machine", "duration_s: 1\nmachine: nowhere.yaml\n", "nowhere.yaml: cannot open file"},
        // A directory opens and then fails to read: it escaped as std::ios_base::failure (fuzz_scenario).
        Bad{"machine_directory", "duration_s: 1\nmachine: /\n", "/: is a directory, not a file"}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace rpem::sim
