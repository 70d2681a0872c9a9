// rpem sim --scenario FILE.yaml --out LOG.csv [--truth TRUTH.csv] [--estimate EST.csv]
//          [--averaged-out AVG.csv --averaged-rate HZ --averaged-jitter X --averaged-seed N]
// rpem sim --scenario FILE.yaml --vesc IFACE --controller-id N [--status-rate-1 HZ …]   (vesc_emulator.hpp)
// rpem sim --scenario FILE.yaml --vesc-tool-out LOG.csv [--vesc-tool-truth T.csv …]       (vesc_tool_out.hpp)
// Simulates the drive of a scenario and writes what the drive would log, the truth beside it and,
// optionally, the estimator's output run in the loop, and the averaged rotor-frame samples a drive that
// averages every control cycle would report (sim/cycle_average.hpp; docs/drive-log.md, "Averaged logs").

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "can_stream.hpp"
#include "commands.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "rpem/can/protocol.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/estimate_log.hpp"
#include "rpem/io/number_format.hpp"
#include "rpem/sim/cycle_average.hpp"
#include "rpem/sim/drive_simulator.hpp"
#include "rpem/sim/truth_log.hpp"
#include "vesc_emulator.hpp"
#include "vesc_tool_out.hpp"

namespace rpem::tools {
namespace {

struct SimOptions {
  std::string scenario;
  std::string out;
  std::string truth;
  std::string estimate;
  std::string averaged_out;
  double averaged_rate_Hz = 200.0;
  double averaged_jitter = 0.3;
  std::uint64_t averaged_seed = 1;
  StreamOptions stream;
  VescEmulatorOptions vesc;
  VescToolOptions vesc_tool;
};

/// What the simulation did: its samples, where they were written (`out`, if a drive log was) and streamed.
std::string drive_sim_summary(std::uint64_t n, const std::string& name, const std::string& out,
                              const TelemetryStreamer* streamer) {
  std::string summary = io::counted(n, "sample") + " of '" + name + "'";
  if (!out.empty()) summary += " written to " + out;
  if (streamer != nullptr) {
    summary += ", streamed as " + io::counted(streamer->frames_sent(), "frame");
    if (streamer->frames_dropped() > 0)
      summary += " (" + std::to_string(streamer->frames_dropped()) + " dropped on purpose)";
  }
  return summary;
}

int run_drive_sim(const SimOptions& o);

/// --vesc-tool-out and --vesc run alone; anything else is the drive simulated (run_drive_sim).
int run_sim(const SimOptions& o) {
  if (!o.vesc_tool.out.empty()) {
    if (!o.out.empty() || !o.averaged_out.empty() || !o.truth.empty() || !o.estimate.empty() ||
        !o.stream.interface.empty() || !o.stream.candump_out.empty() || !o.vesc.interface.empty()) {
      std::fprintf(stderr,
                   "rpem sim: --vesc-tool-out runs alone (its truth: --vesc-tool-truth); drop --out, "
                   "--averaged-out, --truth, --estimate, --can, --candump and --vesc\n");
      return kExitUsage;
    }
    return run_vesc_tool_log(sim::load_scenario(o.scenario), o.vesc_tool);
  }
  if (!o.vesc_tool.truth.empty()) {
    std::fprintf(stderr, "rpem sim: --vesc-tool-truth needs --vesc-tool-out\n");
    return kExitUsage;
  }
  if (!o.vesc.interface.empty()) {
    VescEmulatorOptions vesc = o.vesc;
    vesc.truth = o.truth;
    return run_vesc_emulator(sim::load_scenario(o.scenario), vesc);
  }
  return run_drive_sim(o);
}

/// The drive simulated sample by sample into a drive log, an averaged log, CAN telemetry, the truth and the
/// estimator's log, as the options ask.
int run_drive_sim(const SimOptions& o) {
  sim::DriveSimulator simulator(sim::load_scenario(o.scenario));
  std::optional<io::DriveLogWriter> log;
  if (!o.out.empty()) log.emplace(o.out, simulator.layout());
  std::optional<TelemetryStreamer> streamer;
  if (!o.stream.interface.empty() || !o.stream.candump_out.empty()) streamer.emplace(o.stream);
  std::optional<io::AveragedLogWriter> averaged_log;
  sim::CycleExtractor cycles;
  sim::WindowAverager windows(o.averaged_rate_Hz, o.averaged_jitter, o.averaged_seed);
  if (!o.averaged_out.empty()) {
    const io::DriveLogLayout l = simulator.layout();
    averaged_log.emplace(o.averaged_out, io::AveragedLogLayout{true, l.t_winding, l.t_magnet, false, l.t_coolant});
  }
  if (!log && !streamer && !averaged_log) {
    std::fprintf(
        stderr,
        "rpem sim: give --out LOG.csv, --averaged-out AVG.csv, --vesc-tool-out LOG.csv, --can IFACE or --candump FILE\n");
    return kExitUsage;
  }
  std::optional<sim::TruthLogWriter> truth;
  if (!o.truth.empty()) truth.emplace(o.truth);
  std::optional<io::EstimateLogWriter> est_log;
  std::unique_ptr<core::DriveEstimator> estimator;
  if (!o.estimate.empty()) {
    est_log.emplace(o.estimate);
    const auto& cfg = simulator.scenario().machine;
    estimator = std::make_unique<core::DriveEstimator>(cfg.machine, cfg.estimator);
  }
  if (streamer && o.stream.rate > 0)
    std::fprintf(stderr, "rpem sim: streaming '%s' on %s at %.3g× real time\n", simulator.scenario().name.c_str(),
                 o.stream.interface.empty() ? o.stream.candump_out.c_str() : o.stream.interface.c_str(), o.stream.rate);
  Progress progress("rpem sim");
  io::DriveLogRow row;
  sim::TruthRow truth_row;
  std::uint64_t n = 0;
  const auto total = static_cast<std::uint64_t>(simulator.samples_total());
  while (simulator.next(row, truth_row)) {
    if (log) log->write(row);
    if (averaged_log) {
      if (const auto cycle = cycles.add(row)) {
        if (const auto window = windows.add(*cycle)) averaged_log->write(*window);
      }
    }
    if (streamer) streamer->send(row.sample, can::protocol::status::kPwmEnabled | can::protocol::status::kSimulated);
    if (truth) truth->write(truth_row);
    if (estimator) est_log->write(estimator->step(row.sample), *estimator);
    if ((++n & 0x3FF) == 0) progress.update(n, total);
  }
  if (streamer) streamer->finish();
  progress.finish(
      drive_sim_summary(n, simulator.scenario().name, log ? o.out : std::string(), streamer ? &*streamer : nullptr));
  if (streamer && !streamer->lateness_summary().empty())
    std::fprintf(stderr, "rpem sim: %s\n", streamer->lateness_summary().c_str());
  return kExitOk;
}

}  // namespace

Runner add_sim_command(CLI::App& app) {
  auto opts = std::make_shared<SimOptions>();
  CLI::App* cmd = app.add_subcommand("sim", "Simulate the drive of a scenario and write its drive log");
  cmd->add_option("--scenario", opts->scenario, "scenario YAML (docs/scenarios.md)")->required()->check(CLI::ExistingFile);
  writes_file(cmd->add_option("--out", opts->out, "drive-log CSV to write"));
  writes_file(cmd->add_option("--truth", opts->truth, "also write the true parameters and state (CSV)"));
  writes_file(cmd->add_option("--estimate", opts->estimate, "also run the estimator in the loop and write its CSV"));
  cmd->add_option("--can", opts->stream.interface, "stream the drive's telemetry on this SocketCAN interface, in real time");
  writes_file(
      cmd->add_option("--averaged-out", opts->averaged_out,
                      "also write averaged rotor-frame samples as a drive averaging every control cycle reports them"));
  cmd->add_option("--averaged-rate", opts->averaged_rate_Hz, "mean rate of the averaged samples [Hz]")
      ->check(CLI::Range(50.0, 2000.0));
  cmd->add_option("--averaged-jitter", opts->averaged_jitter, "window lengths uniform in (1 +- jitter)/rate")
      ->check(CLI::Range(0.0, 0.9));
  cmd->add_option("--averaged-seed", opts->averaged_seed, "seed of the window lengths");
  add_stream_options(cmd, opts->stream);
  add_vesc_emulator_options(cmd, opts->vesc);
  add_vesc_tool_options(cmd, opts->vesc_tool);
  return [cmd, opts]() { return cmd->parsed() ? run_sim(*opts) : -1; };
}

}  // namespace rpem::tools
