// Simulator speed: seconds of simulated drive per second of wall time (the "× real time" counter),
// switching fidelity (1 µs plant step, 125 µs control) and averaged fidelity, each with the
// estimator running on every sample, as in `rpem sim --estimate`. Targets: ≥ 20× and ≥ 500×.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/sim/drive_simulator.hpp"

namespace {

using namespace rpem;

sim::Scenario scenario(sim::InverterModel model) {
  sim::Scenario s = sim::paper_scenario();
  s.inverter.model = model;
  s.plant_step_s = model == sim::InverterModel::kSwitching ? 1e-6 : s.sample_period_s;
  s.warmup_s = 0.0;
  s.duration_s = 1.0;
  s.sensors.current_noise_A = 0.01;
  s.sensors.current_lsb_A = 0.005;
  s.sensors.encoder_counts = 65536;
  s.signal(sim::Quantity::kSpeed) = sim::Signal(400.0);
  s.signal(sim::Quantity::kTorque) = sim::Signal(6.52);
  s.signal(sim::Quantity::kUdc) = sim::Signal(565.0);
  return s;
}

void BM_SimulateOneSecond(benchmark::State& state) {
  const auto model = state.range(0) == 0 ? sim::InverterModel::kSwitching : sim::InverterModel::kAveraged;
  const bool with_estimator = state.range(1) != 0;
  const sim::Scenario s = scenario(model);
  double simulated_s = 0.0;
  for (auto _ : state) {
    sim::DriveSimulator d(s);
    core::DriveEstimator est(s.machine.machine, s.machine.estimator);
    io::DriveLogRow row;
    sim::TruthRow truth;
    double sink = 0.0;
    while (d.next(row, truth)) {
      if (with_estimator) sink += est.step(row.sample).psi_m_Wb;
    }
    benchmark::DoNotOptimize(sink);
    simulated_s += s.duration_s;
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
}

BENCHMARK(BM_SimulateOneSecond)
    ->ArgNames({"averaged", "estimator"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ComputeStatistics("min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); })
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
