// rpem figures --out DIR [--config CFG.yaml]
// The paper's analysis figures (Fig_EigenTraj, Fig_sensitivity, fig_PEG_analytical, fig_hesscompstatic)
// for the configured machine.

#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "rpem/analysis/analysis_figures.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::tools {
namespace {

struct FiguresOptions {
  std::string out;
  std::string config;
};

int run_figures(const FiguresOptions& o) {
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
  return [cmd, opts]() { return cmd->parsed() ? run_figures(*opts) : -1; };
}

}  // namespace rpem::tools
