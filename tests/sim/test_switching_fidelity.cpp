// Edge-to-edge switching simulation is more faithful than the fixed 1 µs step, not only faster: the
// closed-loop drive at switching level against a reference with a fixed 10 ns step (Heun with the
// inverter's exact mean voltage per step, the currents' signs taken at each step's start, so zero
// crossings and zero-current clamping are resolved to 10 ns). The largest deviation of the sampled
// rotor-frame current from the reference's, over every sample (docs/scenarios.md, "Integrators"):
//
//   case (60 ms, 20 ms for the map)                 edge to edge   fixed 1 µs
//   paper IPMSM, ideal inverter                        2.8e-10 A      2.4e-8 A
//   paper IPMSM, 2 µs dead time, 1.2/0.96 V drops      1.0e-5 A       1.4e-3 A
//   Beckhoff flux map, ideal inverter                  1.9e-7 A       8.6e-7 A
//   Beckhoff flux map, 1 µs dead time, 0.5/0.4 V drops 3.1e-6 A       1.6e-4 A
//
// With dead time the edge-to-edge deviation is the reference's own: it halves with the reference's
// step (2.1e-5 A at 20 ns, 1.0e-5 A at 10 ns, 6.5e-6 A at 5 ns in the second case).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "rpem/sim/drive_simulator.hpp"
#include "support/data_file.hpp"

namespace rpem::sim {
namespace {

std::vector<core::Vec2> sampled_currents(Scenario s, PlantIntegrator integrator, double step_s) {
  s.integrator = integrator;
  s.plant_step_s = step_s;
  DriveSimulator d(std::move(s));
  io::DriveLogRow row;
  TruthRow truth;
  std::vector<core::Vec2> i;
  while (d.next(row, truth)) i.push_back(truth.i_dq_A);
  return i;
}

double largest_deviation(const std::vector<core::Vec2>& a, const std::vector<core::Vec2>& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, (a[k] - b[k]).norm());
  return worst;
}

struct Deviations {
  double edges_A, fixed_A;
};

Deviations against_reference(const Scenario& s) {
  const auto reference = sampled_currents(s, PlantIntegrator::kFixedStep, 10e-9);
  const Deviations d{largest_deviation(sampled_currents(s, PlantIntegrator::kEdges, 0.0), reference),
                     largest_deviation(sampled_currents(s, PlantIntegrator::kFixedStep, 1e-6), reference)};
  std::printf("%s: largest deviation from the 10 ns reference: edge to edge %.2e A, fixed 1 us %.2e A\n", s.name.c_str(),
              d.edges_A, d.fixed_A);
  return d;
}

/// `s` at a constant operating point, with the inverter's dead time and device drops (diode 0.8× IGBT).
Scenario with_inverter(Scenario s, const char* machine, double speed_rpm, double torque_Nm, double dead_time_s,
                       double drop_V, double duration_s) {
  char name[96];
  std::snprintf(name, sizeof name, "%s, dead time %g s, drop %g V", machine, dead_time_s, drop_V);
  s.name = name;
  s.signal(Quantity::kSpeed) = Signal(speed_rpm);
  s.signal(Quantity::kTorque) = Signal(torque_Nm);
  s.inverter.dead_time_s = dead_time_s;
  s.inverter.v_igbt_V = drop_V;
  s.inverter.v_diode_V = 0.8 * drop_V;
  s.warmup_s = 0.01;
  s.duration_s = duration_s;
  return s;
}

Scenario paper(double dead_time_s, double drop_V) {
  Scenario s = paper_scenario();
  s.signal(Quantity::kUdc) = Signal(565.0);
  return with_inverter(s, "paper IPMSM", 400.0, 6.52, dead_time_s, drop_V, 0.06);
}

TEST(SwitchingFidelity, IdealInverterEdgeToEdgeIsCloserToTheFineReference) {
  const Deviations d = against_reference(paper(0.0, 0.0));
  EXPECT_LT(d.edges_A, 2e-9);
  EXPECT_GT(d.fixed_A, 1e-8);
  EXPECT_LT(d.edges_A, 0.1 * d.fixed_A);
}

TEST(SwitchingFidelity, DeadTimeAndDropsEdgeToEdgeIsCloserToTheFineReference) {
  const Deviations d = against_reference(paper(2e-6, 1.2));
  EXPECT_LT(d.edges_A, 4e-5);
  EXPECT_GT(d.fixed_A, 5e-4);
  EXPECT_LT(d.edges_A, 0.05 * d.fixed_A);
}

Scenario beckhoff(double dead_time_s, double drop_V) {
  Scenario s = load_scenario(test::source_dir() + "/scenarios/diagnose-beckhoff.yaml");
  s.sensors = SensorConfig{};
  return with_inverter(s, "Beckhoff flux map", 300.0, 1.12, dead_time_s, drop_V, 0.02);
}

TEST(SwitchingFidelity, FluxMapEdgeToEdgeIsCloserToTheFineReference) {
  // Error-controlled (relative tolerance 1e-9, the default): the deviation shrinks with the tolerance
  // (1.1e-6 A at 1e-8, 3.4e-8 A at 1e-10, 2.2e-9 A at 1e-11).
  const Deviations ideal = against_reference(beckhoff(0.0, 0.0));
  EXPECT_LT(ideal.edges_A, 4e-7);
  EXPECT_GT(ideal.fixed_A, 4e-7);
  const Deviations d = against_reference(beckhoff(1e-6, 0.5));
  EXPECT_LT(d.edges_A, 1.5e-5);
  EXPECT_GT(d.fixed_A, 5e-5);
  EXPECT_LT(d.edges_A, 0.2 * d.fixed_A);
}

}  // namespace
}  // namespace rpem::sim
