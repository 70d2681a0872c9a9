// Telemetry decode throughput on one core: samples per second through TelemetryDecoder (E2E check,
// sequence check, unscaling), CAN FD (3 samples per frame) and classic (5 frames per sample).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "rpem/can/decoder.hpp"
#include "rpem/can/encoder.hpp"

namespace {

using namespace rpem;

std::vector<can::CanFrame> frames(can::BusMode mode, int samples) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  can::TelemetryEncoder enc(mode, 3);
  std::vector<can::CanFrame> out;
  std::array<can::CanFrame, can::TelemetryEncoder::kMaxFramesPerAdd> buf;
  for (int k = 0; k < samples; ++k) {
    core::DriveSample s;
    s.t_ns = k * 125'000LL;
    s.theta_el_rad = 3 * u(rng);
    s.omega_el_rad_s = 100 * u(rng);
    s.u_dc_V = 220;
    s.u_V = {100 * u(rng), 100 * u(rng), 100 * u(rng)};
    s.i_A = {5 * u(rng), 5 * u(rng), 5 * u(rng)};
    const std::size_t n = enc.add(s, 1, buf);
    out.insert(out.end(), buf.begin(), buf.begin() + static_cast<long>(n));
  }
  return out;
}

void BM_Decode(benchmark::State& state) {
  const auto mode = state.range(0) == 0 ? can::BusMode::kFd : can::BusMode::kClassic;
  const auto input = frames(mode, 30'000);
  std::array<core::DriveSample, 3> out;
  std::int64_t samples = 0;
  for (auto _ : state) {
    can::TelemetryDecoder dec;
    for (const auto& f : input) samples += static_cast<std::int64_t>(dec.decode(f, 0, out));
    benchmark::DoNotOptimize(out);
  }
  state.counters["samples_per_s"] = benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Decode)
    ->ArgName("classic")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ComputeStatistics("min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); })
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
