// rpem figures --out DIR [--config CFG.yaml] [--log LOG.csv|FOLDER [--log-map MAP.yaml]]
// rpem figures --out DIR --thermal-estimate EST.csv [--measured CSV [--magnet-column C] [--winding-column C]]
//              [--judged-after-s T]
// The paper's analysis figures (Fig_EigenTraj, Fig_sensitivity, fig_PEG_analytical, fig_hesscompstatic)
// for the configured machine; with --log also the log's timeline coloured by regime (regimes.png, as
// `rpem diagnose` draws it), for any log `rpem estimate` and `rpem diagnose` read (io::log_source) or a folder of
// them joined as sessions; or,
// with --thermal-estimate, the fused temperatures of `rpem estimate --thermal` against measured ones with
// the ±2σ band (thermal_fused.png; docs/thermal.md, "Figures").

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "commands.hpp"
#include "log_options.hpp"
#include "log_sessions.hpp"
#include "machine_option.hpp"
#include "rpem/analysis/analysis_figures.hpp"
#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/analysis/diagnose/regimes.hpp"
#include "rpem/analysis/thermal/thermal_figure.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/sample_counts.hpp"

namespace rpem::tools {
namespace {

struct FiguresOptions {
  std::string out;
  std::string config;
  std::string log;
  std::string log_map;
  analysis::ThermalFigureInput thermal;
};

int run_figures(const FiguresOptions& o) {
  if (!o.thermal.estimate_csv.empty()) {
    io::create_output_directory(o.out);
    const std::string png = o.out + "/thermal_fused.png";
    const analysis::ThermalFigureCoverage c = analysis::write_thermal_figure(png, o.thermal);
    std::fprintf(stderr, "rpem figures: wrote %s", png.c_str());
    if (!o.thermal.measured_csv.empty()) {
      const auto share = [](double inside) {  // NaN: no measured point was judged (none after --judged-after-s)
        if (std::isnan(inside)) return std::string("no point judged");
        char text[32];
        std::snprintf(text, sizeof text, "%.1f %%", 100.0 * inside);
        return std::string(text);
      };
      std::fprintf(stderr, " (measured inside ±2σ: magnet %s, winding %s)", share(c.magnet).c_str(),
                   share(c.winding).c_str());
    }
    std::fprintf(stderr, "\n");
    return kExitOk;
  }
  const io::MachineConfig cfg = machine_config_or_builtin(o.config, "rpem figures");
  // The log first: a log that cannot be read fails before any figure is drawn.
  std::optional<analysis::LogData> log;
  analysis::LogRegimes regimes;
  if (!o.log.empty()) {
    analysis::LogOptions options = analysis::log_options(cfg);
    options.log_map = o.log_map;
    options.blocks = 2;  // the timeline uses no blocks: the fewest the log's preparation takes, so short logs draw
    options.samples_needed_for =
        "for a timeline: its log is prepared as diagnose prepares one, in 2 blocks of 2 samples at least";
    log = load_log_or_sessions(o.log, cfg.machine, options);
    print_log_read("rpem figures", *log);
    regimes = analysis::classify_regimes(*log, cfg);
    std::fprintf(stderr, "rpem figures: %s\n", io::regime_summary(regimes.counts).c_str());
    for (const std::string& why : regimes.explanations) std::fprintf(stderr, "rpem figures: %s\n", why.c_str());
    if (const std::string note = io::assumed_frame_note(regimes.counts); !note.empty())
      std::fprintf(stderr, "rpem figures: note: %s\n", note.c_str());
  }
  io::create_output_directory(o.out);
  auto files = analysis::write_analysis_figures(o.out, cfg.machine, cfg.estimator.nominal_sample_period_s);
  if (log)
    files.push_back(o.out + "/" + analysis::write_regime_timeline(o.out, *log, regimes, cfg.machine.rated.pole_pairs));
  for (const auto& f : files) std::fprintf(stderr, "rpem figures: wrote %s\n", f.c_str());
  return kExitOk;
}

}  // namespace

Runner add_figures_command(CLI::App& app) {
  auto opts = std::make_shared<FiguresOptions>();
  CLI::App* cmd =
      app.add_subcommand("figures", "Write the paper's analysis figures for a machine (PNG), and a log's regimes");
  cmd->add_option("--out", opts->out, "output directory")->required();
  cmd->add_option("--config", opts->config, "machine YAML (default: built-in paper-ipmsm.yaml)")->check(CLI::ExistingFile);
  add_log_options(*cmd, opts->log, opts->log_map, "also draw this log's timeline coloured by regime (regimes.png)",
                  LogPath::kFileOrSessions);
  CLI::Option* thermal = cmd->add_option("--thermal-estimate", opts->thermal.estimate_csv,
                                         "instead: plot this `rpem estimate --thermal` CSV's fused temperatures with "
                                         "their ±2σ band")
                             ->check(CLI::ExistingFile)
                             ->excludes("--log");
  CLI::Option* measured = cmd->add_option("--measured", opts->thermal.measured_csv,
                                          "CSV with t [s] and measured temperatures [°C] to plot against")
                              ->check(CLI::ExistingFile)
                              ->needs(thermal);
  cmd->add_option("--magnet-column", opts->thermal.magnet_column,
                  "the measured magnet temperature's column (default T_magnet)")
      ->needs(measured);
  cmd->add_option("--winding-column", opts->thermal.winding_column,
                  "the measured winding temperature's column (default T_winding)")
      ->needs(measured);
  cmd->add_option("--judged-after-s", opts->thermal.judged_after_s,
                  "mark where a held-out part begins; coverage counted after it")
      ->needs(thermal);
  return [cmd, opts]() { return cmd->parsed() ? run_figures(*opts) : -1; };
}

}  // namespace rpem::tools
