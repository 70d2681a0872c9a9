// rpem reproduce --out DIR [--only SUBSTRING] [--jobs N]
// Runs the paper's Section V and VI cases with SGA, GNA and PhyInt on the simulated drive and writes
// the figures, the comparison table and reproduce.json.

#include <atomic>
#include <cstdio>
#include <mutex>
#include <thread>

#include "commands.hpp"
#include "rpem/analysis/reproduction_report.hpp"
#include "rpem/io/errors.hpp"

namespace rpem::tools {
namespace {

struct ReproduceOptions {
  std::string out;
  std::string only;
  unsigned jobs = 0;
};

int run_reproduce(const ReproduceOptions& o) {
  std::vector<analysis::ReproductionCase> cases;
  for (auto& c : analysis::paper_cases()) {
    if (o.only.empty() || c.id.find(o.only) != std::string::npos) cases.push_back(std::move(c));
  }
  if (cases.empty()) {
    std::fprintf(stderr, "rpem reproduce: no case matches '%s'\n", o.only.c_str());
    return kExitUsage;
  }
  io::create_output_directory(o.out);
  std::vector<analysis::CaseResult> results(cases.size());
  std::atomic<std::size_t> next{0};
  std::mutex print;
  auto worker = [&] {
    for (std::size_t i; (i = next++) < cases.size();) {
      results[i] = analysis::run_case(cases[i]);
      const std::lock_guard lock(print);
      const auto& runs = results[i].runs;
      std::fprintf(stderr, "rpem reproduce: %-26s convergence SGA %s s, GNA %s s, PhyInt %s s\n", cases[i].id.c_str(),
                   analysis::format_seconds(runs[0].metrics.convergence_time_s).c_str(),
                   analysis::format_seconds(runs[1].metrics.convergence_time_s).c_str(),
                   analysis::format_seconds(runs[2].metrics.convergence_time_s).c_str());
    }
  };
  const unsigned jobs = o.jobs > 0 ? o.jobs : std::max(1U, std::thread::hardware_concurrency());
  std::vector<std::thread> threads;
  for (unsigned j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (auto& t : threads) t.join();

  analysis::write_reproduce_json(o.out + "/reproduce.json", cases, results);
  analysis::write_comparison_markdown(o.out + "/comparison.md", cases, results);
  const auto pngs = analysis::plot_reproduction(o.out, cases, results);
  std::fprintf(stderr, "rpem reproduce: wrote %s/reproduce.json, %s/comparison.md and %zu figures\n", o.out.c_str(),
               o.out.c_str(), pngs.size());
  return kExitOk;
}

}  // namespace

Runner add_reproduce_command(CLI::App& app) {
  auto opts = std::make_shared<ReproduceOptions>();
  CLI::App* cmd = app.add_subcommand("reproduce", "Reproduce the paper's Section V and VI results on the simulated drive");
  cmd->add_option("--out", opts->out, "output directory")->required();
  cmd->add_option("--only", opts->only, "run only the cases whose id contains this text (e.g. V_psim)");
  cmd->add_option("--jobs", opts->jobs, "parallel simulations (default: one per core)");
  return [cmd, opts]() { return cmd->parsed() ? run_reproduce(*opts) : -1; };
}

}  // namespace rpem::tools
