// `rpem diagnose` on a 20 s log at 8 kHz with the temperature columns (160 000 samples;
// scenarios/diagnose-bench.yaml with a hidden 1.5 µs dead time, switching-level simulation, winding and
// magnet temperatures logged at a constant 20 °C): reading the CSV, the diagnosis (calibration, replays,
// screening, Ceres fits, held-out tests, estimator runs and checks) and writing the report, figures,
// diagnosis.json and extended.yaml — the whole job, wall time. Target: ≤ 10 s on this 2-core machine.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "support/hidden_effects.hpp"
#include "rpem/io/drive_log.hpp"

namespace {

using namespace rpem;
namespace fs = std::filesystem;

struct Fixture {
  std::string dir = (fs::temp_directory_path() / "rpem_bench_diagnose").string();
  std::string log = dir + "/log.csv";
  io::MachineConfig config;
  Fixture() {
    fs::create_directories(dir);
    sim::Scenario s = sim::load_scenario(RPEM_SOURCE_DIR "/scenarios/diagnose-bench.yaml");
    s.duration_s = 20.0;
    s.log.temperatures = true;  // the real-shaped log has them (constant here: no figure against them)
    test::hide(s, {"deadtime", 1.5e-6});
    config = s.machine;
    io::DriveLogLayout layout;
    const auto rows = test::simulate(s, &layout);
    io::DriveLogWriter w(log, layout);
    for (const auto& r : rows) w.write(r);
  }
};

void BM_DiagnoseTwentySecondLog(benchmark::State& state) {
  static const Fixture f;
  for (auto _ : state) {
    analysis::LogData log = analysis::load_log(f.log, f.config.machine, {});
    analysis::DiagnoseOptions options;
    options.switching_frequency_Hz = 4000.0;
    const analysis::Diagnosis d = analysis::diagnose(std::move(log), f.config, options);
    analysis::write_diagnosis_json(f.dir + "/diagnosis.json", d, "builtin:paper-ipmsm");
    analysis::write_extended_yaml(f.dir + "/extended.yaml", d, io::builtin_paper_config_text());
    analysis::write_diagnose_report(f.dir, d, "builtin:paper-ipmsm");
    if (d.selection.found.size() != 1) state.SkipWithError("the dead time was not found");
    state.counters["samples"] = static_cast<double>(d.log->size());
  }
}
BENCHMARK(BM_DiagnoseTwentySecondLog)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(5)
    ->ComputeStatistics("max", [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); })
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
