// Simulator speed: seconds of simulated drive per second of CPU time (the "× real time" counters), with
// the estimator running on every sample as in `rpem sim --estimate`.
//
// BM_SwitchingOverAveraged simulates one second at each fidelity in turn — switching (edge to edge) and
// averaged — timing each on this thread's CPU clock, and prints both speeds and their ratio from the
// same run. On the shared VM the host's other load slows both by up to 30 % in CPU time too (the averaged
// model alone measured 405× and 560× within minutes), so only the ratio of interleaved runs compares
// between runs. Target: switching ≥ 0.3 × averaged.
// BM_SimulateOneSecond times each configuration alone, the fixed 1 µs plant step among them.
// BM_EmulatedVescOneSecond: the emulated VESC's drive (`rpem sim --vesc`, scenarios/vesc-6374.yaml, 12.5 kHz
// control) run on demand by polls at 1 kHz and its statuses, averaged and switching inverter alternately
// on this thread's CPU clock: its real-time factor (CPU seconds per drive second; under 1 it keeps up)
// at each fidelity, from the same run.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <vector>

#include "rpem/core/clock.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/sim/drive_simulator.hpp"
#include "rpem/sim/vesc_on_demand.hpp"

namespace {

using namespace rpem;

enum class Fidelity { kSwitchingEdges, kSwitchingFixedStep, kAveraged };

sim::Scenario scenario(Fidelity fidelity) {
  sim::Scenario s = sim::paper_scenario();
  s.inverter.model = fidelity == Fidelity::kAveraged ? sim::InverterModel::kAveraged : sim::InverterModel::kSwitching;
  s.integrator = fidelity == Fidelity::kSwitchingEdges ? sim::PlantIntegrator::kEdges : sim::PlantIntegrator::kFixedStep;
  s.plant_step_s = fidelity == Fidelity::kAveraged ? s.sample_period_s : 1e-6;
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

/// Runs the scenario through, the estimator stepping on every sample if asked.
void simulate(const sim::Scenario& s, bool with_estimator) {
  sim::DriveSimulator d(s);
  core::DriveEstimator est(s.machine.machine, s.machine.estimator);
  io::DriveLogRow row;
  sim::TruthRow truth;
  double sink = 0.0;
  while (d.next(row, truth)) {
    if (with_estimator) sink += est.step(row.sample).psi_m_Wb;
  }
  benchmark::DoNotOptimize(sink);
}

double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + rpem::core::to_seconds(ts.tv_nsec);
}

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void BM_SimulateOneSecond(benchmark::State& state) {
  const auto fidelity = static_cast<Fidelity>(state.range(0));
  const bool with_estimator = state.range(1) != 0;
  const sim::Scenario s = scenario(fidelity);
  double simulated_s = 0.0;
  for (auto _ : state) {
    simulate(s, with_estimator);
    simulated_s += s.duration_s;
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
}

void BM_SwitchingOverAveraged(benchmark::State& state) {
  const sim::Scenario switching = scenario(Fidelity::kSwitchingEdges), averaged = scenario(Fidelity::kAveraged);
  double switching_cpu_s = 0.0, averaged_cpu_s = 0.0;
  for (auto _ : state) {
    const double t0 = thread_cpu_s();
    simulate(averaged, true);
    const double t1 = thread_cpu_s();
    simulate(switching, true);
    switching_cpu_s += thread_cpu_s() - t1;
    averaged_cpu_s += t1 - t0;
  }
  const auto seconds = static_cast<double>(state.iterations()) * switching.duration_s;
  state.counters["switching_x_real_time"] = seconds / switching_cpu_s;
  state.counters["averaged_x_real_time"] = seconds / averaged_cpu_s;
  state.counters["ratio"] = averaged_cpu_s / switching_cpu_s;
}

sim::Scenario vesc_scenario(Fidelity fidelity) {
  sim::Scenario s = sim::load_scenario(RPEM_SOURCE_DIR "/scenarios/vesc-6374.yaml");
  s.warmup_s = 0.0;
  s.duration_s = 2.0;
  if (fidelity != Fidelity::kAveraged) {
    s.inverter.model = sim::InverterModel::kSwitching;
    s.integrator = sim::PlantIntegrator::kEdges;
  }
  return s;
}

/// CPU seconds for one second of the emulated drive, polled at 1 kHz.
double emulate_one_second(const sim::Scenario& s) {
  sim::OnDemandVesc::Settings settings;
  settings.motor = {17, 40.0};
  sim::OnDemandVesc drive(s, settings);
  double sink = 0.0;
  auto emit = [&](const can::vesc::Status& st) { sink += st.erpm; };
  const double t0 = thread_cpu_s();
  for (std::int64_t t = 1'000'000; t <= 1'000'000'000; t += 1'000'000) {
    const auto r = drive.poll(t, emit);
    if (!r) break;
    sink += r->values.i_q_A;
  }
  benchmark::DoNotOptimize(sink);
  return thread_cpu_s() - t0;
}

void BM_EmulatedVescOneSecond(benchmark::State& state) {
  const sim::Scenario averaged = vesc_scenario(Fidelity::kAveraged), switching = vesc_scenario(Fidelity::kSwitchingEdges);
  double averaged_cpu_s = 0.0, switching_cpu_s = 0.0;
  for (auto _ : state) {
    averaged_cpu_s += emulate_one_second(averaged);
    switching_cpu_s += emulate_one_second(switching);
  }
  const auto seconds = static_cast<double>(state.iterations());
  state.counters["averaged_real_time_factor"] = averaged_cpu_s / seconds;
  state.counters["switching_real_time_factor"] = switching_cpu_s / seconds;
}

BENCHMARK(BM_EmulatedVescOneSecond)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

BENCHMARK(BM_SwitchingOverAveraged)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->Repetitions(5)
    ->ComputeStatistics("min", min_of)
    ->ReportAggregatesOnly(true);

BENCHMARK(BM_SimulateOneSecond)
    ->ArgNames({"fidelity", "estimator"})
    ->Args({static_cast<int>(Fidelity::kSwitchingEdges), 1})
    ->Args({static_cast<int>(Fidelity::kSwitchingFixedStep), 1})
    ->Args({static_cast<int>(Fidelity::kAveraged), 1})
    ->Args({static_cast<int>(Fidelity::kAveraged), 0})
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ComputeStatistics("min", min_of)
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
