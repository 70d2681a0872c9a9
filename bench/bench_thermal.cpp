// The thermal fusion's cost in rpemd's loop (issue 24, item 6: the filter update ≤ 1 µs; the loop's latency
// unchanged). Estimates are pre-computed by DriveEstimator over the model's phase samples at 8 kHz
// (tests/support/model_data.hpp) and replayed from memory.
//
//   BM_FusionPerSample     ThermalFusion::step per estimator sample, the filter's step (1 s) included
//                          amortised: what the loop pays per sample on average
//   BM_FilterStep          one filter step: exact network step (matrix exponential), covariance prediction,
//                          both parameter observations and a winding sensor (ThermalFusion::apply), timed as
//                          a batch of kRecordedSteps prepared steps on this thread's CPU clock: what a step
//                          costs, without the harness's per-step timer reads
//   BM_FilterStepTwoNodes  the same with a 2-node network (`rpem thermal fit`'s default), its own steps
//   BM_FilterStepPaused    the same steps one at a time between PauseTiming/ResumeTiming (how this file first
//                          measured it), and BM_PauseResumePair an empty pair: the harness's share of that
//   BM_SampleWithFusion    the estimator's step alone and with the fusion after it, alternating blocks on the
//                          same samples, each timed on this thread's CPU clock: both and their ratio, one run

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <vector>

#include "bench_support.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/thermal_fusion.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/paper_thermal.hpp"

namespace {

using namespace rpem;

constexpr int kSamples = 8 * 8000;  // 8 s at 8 kHz: eight filter steps per pass
constexpr double kPeriod_s = 125e-6;

const std::vector<core::DriveSample>& samples() {
  static const std::vector<core::DriveSample> s = bench::paper_drive_samples(kSamples);
  return s;
}

const std::vector<core::Estimate>& estimates() {
  static const std::vector<core::Estimate> e = [] {
    core::DriveEstimator est(test::paper_machine_si(), test::paper_settings());
    std::vector<core::Estimate> v;
    for (const core::DriveSample& s : samples()) v.push_back(est.step(s));
    return v;
  }();
  return e;
}

/// The test network with the filter's default step (1 s) and settling: rpemd's configuration.
core::ThermalFusionConfig loop_config() {
  core::ThermalFusionConfig c = test::paper_thermal_fusion();
  c.observer.period_s = 1.0;
  c.observer.settle_time_constants = 5.0;
  c.filter.gate_sigma = 5.0;
  return c;
}

using bench::max_of;
using bench::thread_cpu_s;

core::ThermalSample sample() {
  core::ThermalSample s;
  s.dt_s = kPeriod_s;
  s.coolant_C = 40.0;
  return s;
}

void BM_FusionPerSample(benchmark::State& state) {
  const std::vector<core::Estimate>& e = estimates();
  core::ThermalFusion fusion(loop_config(), test::paper_base(), test::paper_machine_si());
  const core::ThermalSample s = sample();
  std::size_t k = 0;
  for (auto _ : state) {
    fusion.step(e[k], s);
    benchmark::DoNotOptimize(fusion.estimate());
    if (++k == e.size()) k = 0;
  }
  state.counters["observations"] = static_cast<double>(fusion.estimate().observations_accepted);
  state.SetItemsProcessed(state.iterations());
}

/// One step's data as the loop gives it: the 1 s means of a load that moves a little (the current's mean never
/// repeats, so the network's exponential is new at every step), ψ̂m and r̂s each an observation at the filter's
/// own prediction (accepted: inside the gate) and a winding sensor.
core::ThermalStepData step_data(const core::ThermalEstimate& out, std::int64_t k) {
  core::ThermalStepData d;
  d.t_ns = (k + 1) * 1'000'000'000;
  d.load.dt_s = 1.0;
  d.load.current_sq_A2 = 30.0 * (1.0 + 0.05 * std::sin(0.37 * static_cast<double>(k)));
  d.load.basis = {0.4, 0.16, 0.1};
  d.load.coolant_C = 40.0;
  const double t_m = out.started ? out.magnet_node().t_C : 40.0, t_w = out.started ? out.winding_node().t_C : 40.0;
  d.parameter[static_cast<std::size_t>(core::kPsiM)] = {true, 1.14 * (1.0 - 0.0012 * (t_m - 20.0)), 0.0, 2.25, 1e-6, 1e-6,
                                                        2.0};
  d.parameter[static_cast<std::size_t>(core::kRs)] = {true, 2.25 * (1.0 + 0.00393 * (t_w - 20.0)), 0.0, 1.14, 1e-4, 1e-4,
                                                      2.0};
  d.winding_sensor_C = t_w;
  d.psi_m_Wb = d.parameter[static_cast<std::size_t>(core::kPsiM)].value;
  d.r_s_Ohm = d.parameter[static_cast<std::size_t>(core::kRs)].value;
  return d;
}

constexpr int kRecordedSteps = 1000;  // 1000 s of filter steps: the network heats most of the way

/// kRecordedSteps steps recorded from a run of a filter with configuration c.
std::vector<core::ThermalStepData> record_steps(const core::ThermalFusionConfig& c) {
  core::ThermalFusion fusion(c, test::paper_base(), test::paper_machine_si());
  std::vector<core::ThermalStepData> steps;
  for (int k = 0; k < kRecordedSteps; ++k) {
    steps.push_back(step_data(fusion.estimate(), k));
    fusion.apply(steps.back());
  }
  return steps;
}

/// The loop configuration's steps, recorded once and replayed identically by every batch.
const std::vector<core::ThermalStepData>& recorded_steps() {
  static const std::vector<core::ThermalStepData> v = record_steps(loop_config());
  return v;
}

/// The loop's configuration with `rpem thermal fit`'s default topology: two nodes, winding and magnet (the
/// network's exponential on their 2×2 block, core/src/thermal_network.cpp).
core::ThermalFusionConfig two_node_config() {
  core::ThermalFusionConfig c = loop_config();
  core::ThermalNetwork& n = c.filter.network;
  n.nodes = 2;
  n.winding = 0, n.magnet = 1;
  n.capacitance_J_per_K << 3000.0, 7000.0, 1.0, 1.0;
  n.to_coolant_W_per_K << 30.0, 4.0, 0.0, 0.0;
  n.between_W_per_K.setZero();
  n.between_W_per_K(0, 1) = n.between_W_per_K(1, 0) = 12.0;
  n.loss_at_base_W.setZero();
  n.loss_at_base_W(static_cast<int>(core::LossForm::kIronEddy), 0) = 100.0;
  n.loss_at_base_W(static_cast<int>(core::LossForm::kMagnetEddy), 1) = 20.0;
  return c;
}

/// Its own steps (observations at its own predictions, so that they are accepted as the loop's are).
const std::vector<core::ThermalStepData>& recorded_two_node_steps() {
  static const std::vector<core::ThermalStepData> v = record_steps(two_node_config());
  return v;
}

/// The loop's configuration with every node's disturbance Gauss–Markov (eq. 14.19): the decay's exponentials
/// on every step, the filter's dearest form.
core::ThermalFusionConfig gauss_markov_config() {
  core::ThermalFusionConfig c = loop_config();
  c.filter.disturbance_time_constant_s.setConstant(1000.0);
  return c;
}

/// ... and the winding sensor lagging by 10 s (eq. 14.22): its observation sees the winding's rate (h_d) and its
/// lag is carried over every step — every form the filter has, at once.
core::ThermalFusionConfig lagged_sensor_config() {
  core::ThermalFusionConfig c = gauss_markov_config();
  c.winding_sensor_time_constant_s = 10.0;
  return c;
}

/// ... and the winding node standing for that sensor's reading (eq. 14.24): the winding's readout g·[T; d] in the
/// ψ̂m and r̂s observations and in the report, every step.
core::ThermalFusionConfig reading_node_config() {
  core::ThermalFusionConfig c = lagged_sensor_config();
  c.winding_node_is_reading = true;
  return c;
}

void filter_steps(benchmark::State& state, const core::ThermalFusionConfig& config,
                  const std::vector<core::ThermalStepData>& steps = recorded_steps()) {
  const core::ThermalFusion initial(config, test::paper_base(), test::paper_machine_si());
  core::ThermalFusion fusion = initial;
  double cpu_s = 0.0;
  for (auto _ : state) {
    fusion = initial;
    const double t0 = thread_cpu_s();
    for (const core::ThermalStepData& d : steps) {
      fusion.apply(d);
      benchmark::DoNotOptimize(fusion.estimate());
    }
    cpu_s += thread_cpu_s() - t0;
  }
  state.counters["step_ns"] = 1e9 * cpu_s / (static_cast<double>(state.iterations()) * kRecordedSteps);
  state.counters["accepted"] = static_cast<double>(fusion.estimate().observations_accepted);
  state.counters["rejected"] = static_cast<double>(fusion.estimate().observations_rejected);
  state.counters["held"] = static_cast<double>(fusion.estimate().winding_readings_held);
}

/// The loop's steps with the winding sensor at a 1 K resolution: most steps read the value of the step before, so
/// the held-reading check (eq. 14.28) runs its dearer path, the reading's innovation variance, on each.
const std::vector<core::ThermalStepData>& recorded_steps_at_1K() {
  static const std::vector<core::ThermalStepData> v = [] {
    std::vector<core::ThermalStepData> s = recorded_steps();
    for (core::ThermalStepData& d : s) d.winding_sensor_C = std::round(d.winding_sensor_C);
    return s;
  }();
  return v;
}

void BM_FilterStep(benchmark::State& state) { filter_steps(state, loop_config()); }
void BM_FilterStepSensorAt1K(benchmark::State& state) { filter_steps(state, loop_config(), recorded_steps_at_1K()); }
void BM_FilterStepGaussMarkov(benchmark::State& state) { filter_steps(state, gauss_markov_config()); }
void BM_FilterStepLaggedSensor(benchmark::State& state) { filter_steps(state, lagged_sensor_config()); }
void BM_FilterStepReadingNode(benchmark::State& state) { filter_steps(state, reading_node_config()); }
void BM_FilterStepTwoNodes(benchmark::State& state) { filter_steps(state, two_node_config(), recorded_two_node_steps()); }

void BM_FilterStepPaused(benchmark::State& state) {
  const std::vector<core::ThermalStepData>& steps = recorded_steps();
  const core::ThermalFusion initial(loop_config(), test::paper_base(), test::paper_machine_si());
  core::ThermalFusion fusion = initial;
  std::size_t k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    if (k == steps.size()) {
      fusion = initial;
      k = 0;
    }
    state.ResumeTiming();
    fusion.apply(steps[k++]);
    benchmark::DoNotOptimize(fusion.estimate());
  }
}

void BM_PauseResumePair(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    state.ResumeTiming();
  }
}

void BM_SampleWithFusion(benchmark::State& state) {
  const std::vector<core::DriveSample>& x = samples();
  core::DriveEstimator alone(test::paper_machine_si(), test::paper_settings());
  core::DriveEstimator fused(test::paper_machine_si(), test::paper_settings());
  core::ThermalFusion fusion(loop_config(), test::paper_base(), test::paper_machine_si());
  const core::ThermalSample s = sample();
  double alone_s = 0.0, fused_s = 0.0;
  std::int64_t pass_ns = 0;
  constexpr std::size_t kBlock = 8000;  // one second of samples per block
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t begin = k;
    const double t0 = thread_cpu_s();
    for (std::size_t j = 0; j < kBlock; ++j) {
      core::DriveSample d = x[begin + j];
      d.t_ns += pass_ns;
      benchmark::DoNotOptimize(alone.step(d));
    }
    const double t1 = thread_cpu_s();
    for (std::size_t j = 0; j < kBlock; ++j) {
      core::DriveSample d = x[begin + j];
      d.t_ns += pass_ns;
      fusion.step(fused.step(d), s);
      benchmark::DoNotOptimize(fusion.estimate());
    }
    fused_s += thread_cpu_s() - t1;
    alone_s += t1 - t0;
    k += kBlock;
    if (k + kBlock > x.size()) {
      k = 0;
      pass_ns += x.back().t_ns - x.front().t_ns + 125'000;
    }
  }
  const double n = static_cast<double>(state.iterations()) * kBlock;
  state.counters["alone_ns"] = 1e9 * alone_s / n;
  state.counters["fused_ns"] = 1e9 * fused_s / n;
  state.counters["fusion_ns"] = 1e9 * (fused_s - alone_s) / n;
  state.counters["ratio"] = fused_s / alone_s;
}

BENCHMARK(BM_FusionPerSample)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStep)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStepSensorAt1K)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStepGaussMarkov)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStepLaggedSensor)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStepReadingNode)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStepTwoNodes)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_FilterStepPaused)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_PauseResumePair)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);
BENCHMARK(BM_SampleWithFusion)->MinTime(1.0)->Repetitions(10)->ComputeStatistics("max", max_of)->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
