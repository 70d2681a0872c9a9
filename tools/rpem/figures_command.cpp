// rpem figures --out DIR [--config CFG.yaml]
// rpem figures --out DIR --thermal-estimate EST.csv [--measured CSV [--magnet-column C] [--winding-column C]]
//              [--judged-after-s T]
// The paper's analysis figures (Fig_EigenTraj, Fig_sensitivity, fig_PEG_analytical, fig_hesscompstatic)
// for the configured machine; or, with --thermal-estimate, the fused temperatures of `rpem estimate --thermal`
// against measured ones with the ±2σ band (thermal_fused.png; docs/thermal.md, "Figures").

#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "rpem/analysis/analysis_figures.hpp"
#include "rpem/analysis/thermal/thermal_figure.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::tools {
namespace {

struct FiguresOptions {
  std::string out;
  std::string config;
  analysis::ThermalFigureInput thermal;
};

int run_figures(const FiguresOptions& o) {
  if (!o.thermal.estimate_csv.empty()) {
    std::filesystem::create_directories(o.out);
    const std::string png = o.out + "/thermal_fused.png";
    const analysis::ThermalFigureCoverage c = analysis::write_thermal_figure(png, o.thermal);
    std::fprintf(stderr, "rpem figures: wrote %s", png.c_str());
    if (!o.thermal.measured_csv.empty()) {
      std::fprintf(stderr, " (measured inside ±2σ: magnet %.1f %%, winding %.1f %%)", 100.0 * c.magnet, 100.0 * c.winding);
    }
    std::fprintf(stderr, "\n");
    return kExitOk;
  }
  const io::MachineConfig cfg = o.config.empty() ? io::builtin_paper_config() : io::load_machine_config(o.config);
  std::filesystem::create_directories(o.out);
  const auto files = analysis::write_analysis_figures(o.out, cfg.machine, cfg.estimator.nominal_sample_period_s);
  for (const auto& f : files) std::fprintf(stderr, "rpem figures: wrote %s\n", f.c_str());
  return kExitOk;
}

}  // namespace

Runner add_figures_command(CLI::App& app) {
  auto opts = std::make_shared<FiguresOptions>();
  CLI::App* cmd = app.add_subcommand("figures", "Write the paper's analysis figures for a machine (PNG)");
  cmd->add_option("--out", opts->out, "output directory")->required();
  cmd->add_option("--config", opts->config, "machine YAML (default: built-in paper-ipmsm.yaml)")->check(CLI::ExistingFile);
  cmd->add_option("--thermal-estimate", opts->thermal.estimate_csv,
                  "instead: plot this `rpem estimate --thermal` CSV's fused temperatures with their ±2σ band")
      ->check(CLI::ExistingFile);
  cmd->add_option("--measured", opts->thermal.measured_csv, "CSV with t [s] and measured temperatures [°C] to plot against")
      ->check(CLI::ExistingFile);
  cmd->add_option("--magnet-column", opts->thermal.magnet_column, "the measured magnet temperature's column (default T_magnet)");
  cmd->add_option("--winding-column", opts->thermal.winding_column, "the measured winding temperature's column (default T_winding)");
  cmd->add_option("--judged-after-s", opts->thermal.judged_after_s, "mark where a held-out part begins; coverage counted after it");
  return [cmd, opts]() { return cmd->parsed() ? run_figures(*opts) : -1; };
}

}  // namespace rpem::tools
