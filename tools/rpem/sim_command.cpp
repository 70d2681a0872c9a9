// rpem sim --scenario FILE.yaml --out LOG.csv [--truth TRUTH.csv] [--estimate EST.csv]
// Simulates the drive of a scenario and writes what the drive would log, the truth beside it and,
// optionally, the estimator's output run in the loop.

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "progress.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/estimate_log.hpp"
#include "rpem/sim/drive_simulator.hpp"
#include "rpem/sim/truth_log.hpp"

namespace rpem::tools {
namespace {

struct SimOptions {
  std::string scenario;
  std::string out;
  std::string truth;
  std::string estimate;
};

int run_sim(const SimOptions& o) {
  sim::DriveSimulator simulator(sim::load_scenario(o.scenario));
  io::DriveLogWriter log(o.out, simulator.layout());
  std::optional<sim::TruthLogWriter> truth;
  if (!o.truth.empty()) truth.emplace(o.truth);
  std::optional<io::EstimateLogWriter> est_log;
  std::unique_ptr<core::DriveEstimator> estimator;
  if (!o.estimate.empty()) {
    est_log.emplace(o.estimate);
    const auto& cfg = simulator.scenario().machine;
    estimator = std::make_unique<core::DriveEstimator>(cfg.machine, cfg.estimator);
  }
  Progress progress("rpem sim");
  io::DriveLogRow row;
  sim::TruthRow truth_row;
  std::uint64_t n = 0;
  const auto total = static_cast<std::uint64_t>(simulator.samples_total());
  while (simulator.next(row, truth_row)) {
    log.write(row);
    if (truth) truth->write(truth_row);
    if (estimator) est_log->write(estimator->step(row.sample), *estimator);
    if ((++n & 0x3FF) == 0) progress.update(n, total);
  }
  char summary[160];
  std::snprintf(summary, sizeof summary, "%llu samples of '%s' written to %s", static_cast<unsigned long long>(n),
                simulator.scenario().name.c_str(), o.out.c_str());
  progress.finish(summary);
  return kExitOk;
}

}  // namespace

Runner add_sim_command(CLI::App& app) {
  auto opts = std::make_shared<SimOptions>();
  CLI::App* cmd = app.add_subcommand("sim", "Simulate the drive of a scenario and write its drive log");
  cmd->add_option("--scenario", opts->scenario, "scenario YAML (docs/scenarios.md)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", opts->out, "drive-log CSV to write")->required();
  cmd->add_option("--truth", opts->truth, "also write the true parameters and state (CSV)");
  cmd->add_option("--estimate", opts->estimate, "also run the estimator in the loop and write its CSV");
  return [cmd, opts]() { return cmd->parsed() ? run_sim(*opts) : -1; };
}

}  // namespace rpem::tools
