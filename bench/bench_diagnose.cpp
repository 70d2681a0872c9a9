// `rpem diagnose` on a 20 s log at 8 kHz with the temperature columns (160 000 samples;
// scenarios/diagnose-bench.yaml with a hidden 1.5 µs dead time, switching-level simulation, winding and
// magnet temperatures logged at a constant 20 °C): reading the CSV, the diagnosis (calibration, replays,
// screening, Ceres fits, held-out tests, estimator runs and checks) and writing the report, figures,
// diagnosis.json and extended.yaml — the whole job, wall time. Target: ≤ 10 s on this 2-core machine.
//
// And a VESC Tool realtime-data log of 10 000 rows (issue 23 item 7; target ≤ 2 s): reading it (header detection,
// the column map, midnight), the regime classification, the steady-state diagnosis and the outputs.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/io/drive_log.hpp"
#include "support/hidden_effects.hpp"
#include "support/vesc_tool_vectors.hpp"

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

/// A VESC Tool 1.20 log of `rows` rows read at 11 Hz (windows (1 ± 0.5)/11 s), starting at 23:55 so that
/// ms_today wraps at midnight, of a 6374 outrunner whose ψm is 20 % and R_s 20 % off the configuration
/// (config/vesc-6374-outrunner.yaml): a 60 s cycle of standstill with the bridge off, a start at 20 A,
/// cruising at 5 A, coasting with the bridge off, regenerative braking and coasting at zero current. Each row
/// is the steady state of its window's mean operating point (a tiny inductance: the window's transients are
/// over), its current with 0.05 A of noise, written as VESC Tool writes a row (tests/support/vesc_tool_vectors).
struct VescToolLog {
  std::string dir = (fs::temp_directory_path() / "rpem_bench_diagnose_vesc").string();
  std::string log = dir + "/vesc_tool.csv";
  io::MachineConfig config = io::load_machine_config(RPEM_SOURCE_DIR "/config/vesc-6374-outrunner.yaml");
  std::string config_text;  ///< the file's text, in which extended.yaml replaces the calibrated constants
  explicit VescToolLog(int rows) {
    std::ostringstream text;
    text << std::ifstream(RPEM_SOURCE_DIR "/config/vesc-6374-outrunner.yaml").rdbuf();
    config_text = text.str();
    fs::create_directories(dir);
    const double psi = 0.8 * config.machine.psi_m_Wb, r = 1.2 * config.machine.r_s_Ohm, l = config.machine.l_q_H;
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> jitter(-0.5, 0.5);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::ofstream out(log);
    out << test::vesc_tool::kHeader120;
    double t = 0.0;
    constexpr long kStartMs = (23L * 3600 + 55 * 60) * 1000;
    for (int k = 0; k < rows; ++k) {
      const double window = (1.0 + jitter(rng)) / 11.0, mid = std::fmod(t + 0.5 * window, 60.0);
      t += window;
      // The cycle: speed [rad/s, electrical], current set point [A], whether the bridge modulates.
      double w = 0.0, i_q = 0.0;
      bool on = true;
      if (mid < 5.0) {
        on = false;
      } else if (mid < 15.0) {
        w = 200.0 * (mid - 5.0), i_q = 20.0;
      } else if (mid < 35.0) {
        w = 2000.0, i_q = 5.0;
      } else if (mid < 45.0) {
        w = 2000.0 - 80.0 * (mid - 35.0), on = false;
      } else if (mid < 55.0) {
        w = 1200.0 - 90.0 * (mid - 45.0), i_q = -15.0;
      } else {
        w = 300.0;
      }
      const double i_d = on ? noise(rng) : 0.0, iq = on ? i_q + noise(rng) : 0.0;
      const double u_d = on ? r * i_d - w * l * iq : 0.0, u_q = on ? r * iq + w * l * i_d + w * psi : 0.0;
      const long ms = (kStartMs + std::lround(1000.0 * t)) % 86'400'000L;
      out << test::vesc_tool::row120(ms, i_d, iq, w * 60.0 / (2.0 * core::kPi), u_d, u_q);
    }
  }
};

void BM_DiagnoseVescToolLog(benchmark::State& state) {
  static const VescToolLog f(10'000);
  for (auto _ : state) {
    analysis::LogData log = analysis::load_log(f.log, f.config.machine, {});
    const analysis::Diagnosis d = analysis::diagnose(std::move(log), f.config, {});
    analysis::write_diagnosis_json(f.dir + "/diagnosis.json", d, "config/vesc-6374-outrunner.yaml");
    analysis::write_extended_yaml(f.dir + "/extended.yaml", d, f.config_text);
    analysis::write_diagnose_report(f.dir, d, "config/vesc-6374-outrunner.yaml");
    // The first row only opens the first window (docs/drive-log.md, "Averaging"): 9 999 samples.
    if (d.log->size() != 9'999) state.SkipWithError("not every row was read");
    if (!d.calibration.identifiable[0] ||
        std::abs(d.calibration.value[0] / (0.8 * f.config.machine.psi_m_Wb) - 1.0) > 0.02) {
      state.SkipWithError("ψm was not calibrated within 2 %");
    }
    state.counters["rows"] = static_cast<double>(d.log->size());
    state.counters["bridge_off"] = static_cast<double>(d.regimes.counts.regimes[core::Regime::kBridgeOff]);
  }
}
BENCHMARK(BM_DiagnoseVescToolLog)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(5)
    ->ComputeStatistics("max", [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); })
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
