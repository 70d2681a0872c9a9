// rpem estimate --log LOG.csv [--log-map MAP.yaml] --config CFG.yaml --out EST.csv [--algorithm sga|gna|phyint]
//              [--every N]
// Runs the estimator offline over a drive log, exactly as rpemd would run it online: a log of instantaneous
// samples through DriveEstimator, a log of averaged samples (our averaged log, VESC Tool's realtime log, a
// map of averaged samples; docs/drive-log.md) through AveragedDriveEstimator.

#include <cstdio>
#include <optional>
#include <string>

#include "commands.hpp"
#include "progress.hpp"
#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/estimate_log.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/sample_counts.hpp"

namespace rpem::tools {
namespace {

struct EstimateOptions {
  std::string log;
  std::string log_map;
  std::string config;
  std::string out;
  std::string algorithm;
  long every = 1;
};

/// What the run did, for its summary on stderr: the last estimate and the samples per regime.
struct Tally {
  io::SampleCounts counts;
  core::Estimate last;
  void count(const core::Estimate& e) {
    last = e;
    counts.add(e);
  }
  [[nodiscard]] std::string summary(core::Algorithm a, const char* kind) const {
    char text[256];
    std::snprintf(text, sizeof text, "%llu %s, psi_m = %.5f Wb, r_s = %.5f Ohm (%s), %llu resyncs",
                  static_cast<unsigned long long>(counts.samples), kind, last.psi_m_Wb, last.r_s_Ohm, io::to_string(a),
                  static_cast<unsigned long long>(counts.resyncs));
    return text;
  }
  /// The regimes' counts, and why, where more than a tenth of the samples adapted nothing.
  void explain() const {
    std::fprintf(stderr, "rpem estimate: %s\n", io::regime_summary(counts).c_str());
    for (const std::string& why : io::exclusion_explanations(counts)) std::fprintf(stderr, "rpem estimate: %s\n", why.c_str());
  }
};

int run_averaged(const EstimateOptions& o, const io::LogSource& source, const io::MachineConfig& cfg,
                 const std::string& config_name) {
  io::AveragedLogRead read;
  const std::vector<core::AveragedSample> samples =
      io::read_averaged_log(o.log, source.map, io::machine_limits(cfg.machine), &read);
  std::fprintf(stderr, "rpem estimate: %s\n", io::describe(source, read).c_str());
  io::check_averaged_supports(cfg, config_name, read.layout.u_dc, o.log);
  io::EstimateLogWriter writer(o.out);
  core::AveragedDriveEstimator estimator(cfg.machine, cfg.estimator);
  Tally tally;
  tally.counts.averaged = true;
  for (const core::AveragedSample& s : samples) {
    const core::Estimate e = estimator.step(s);
    if (tally.counts.samples % static_cast<std::uint64_t>(o.every) == 0) writer.write(e, estimator.core());
    tally.count(e);
  }
  std::fprintf(stderr, "rpem estimate: %s\n", tally.summary(cfg.estimator.algorithm, "averaged samples").c_str());
  tally.explain();
  return kExitOk;
}

int run_estimate(const EstimateOptions& o) {
  io::MachineConfig cfg = o.config.empty() ? io::builtin_paper_config() : io::load_machine_config(o.config);
  if (!o.algorithm.empty()) cfg.estimator.algorithm = io::parse_algorithm(o.algorithm);
  const std::string config_name = o.config.empty() ? "builtin:paper-ipmsm" : o.config;
  const io::LogSource source = io::log_source(o.log, o.log_map);
  if (source.averaged()) return run_averaged(o, source, cfg, config_name);

  io::DriveLogReader reader(o.log, source.map, io::machine_limits(cfg.machine));
  if (!source.map.columns_optional) std::fprintf(stderr, "rpem estimate: reading %s as %s\n", o.log.c_str(), source.format.c_str());
  io::check_log_supports(cfg, config_name, reader.layout().u_dc, o.log);
  io::EstimateLogWriter writer(o.out);
  core::DriveEstimator estimator(cfg.machine, cfg.estimator);
  Progress progress("rpem estimate");

  io::DriveLogRow row;
  Tally tally;
  while (reader.next(row)) {
    const core::Estimate e = estimator.step(row.sample);
    if (tally.counts.samples % static_cast<std::uint64_t>(o.every) == 0) writer.write(e, estimator);
    tally.count(e);
    if ((tally.counts.samples & 0xFFF) == 0) progress.update(reader.bytes_read(), reader.bytes_total());
  }
  progress.finish(tally.summary(cfg.estimator.algorithm, "samples") + io::describe(reader.reader().repairs()));
  tally.explain();
  return kExitOk;
}

}  // namespace

Runner add_estimate_command(CLI::App& app) {
  auto opts = std::make_shared<EstimateOptions>();
  CLI::App* cmd = app.add_subcommand("estimate", "Run the RPEM estimator offline over a drive log");
  cmd->add_option("--log", opts->log,
                  "drive log, averaged log or VESC Tool realtime log (detected by its header), or any CSV with --log-map "
                  "(docs/drive-log.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--log-map", opts->log_map, "column map (YAML) saying how to read --log (docs/drive-log.md, \"Column maps\")")
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", opts->config, "machine and estimator YAML (default: built-in paper-ipmsm.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", opts->out, "estimate CSV to write")->required();
  cmd->add_option("--algorithm", opts->algorithm, "override the configured gain algorithm")
      ->check(CLI::IsMember({"sga", "gna", "phyint"}));
  cmd->add_option("--every", opts->every, "write every N-th sample")->check(CLI::PositiveNumber);
  return [cmd, opts]() { return cmd->parsed() ? run_estimate(*opts) : -1; };
}

}  // namespace rpem::tools
