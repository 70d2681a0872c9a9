#include "rpem/analysis/reproduction_report.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "rpem/analysis/gnuplot.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {
namespace {

/// A number with `decimals` places and an optional prefix ("~" for the paper's approximate values).
std::string fmt(std::optional<double> v, int decimals = 2, const char* prefix = "") {
  if (!v) return "—";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s%.*f", prefix, decimals, *v);
  return buf;
}

const CaseResult& result_of(const std::vector<CaseResult>& results, const std::string& id) {
  for (const CaseResult& r : results) {
    if (r.case_id == id) return r;
  }
  throw std::runtime_error("no result for case " + id);
}

}  // namespace

void write_reproduce_json(const std::string& path, const std::vector<ReproductionCase>& cases,
                          const std::vector<CaseResult>& results) {
  nlohmann::json out = nlohmann::json::array();
  for (const ReproductionCase& c : cases) {
    const CaseResult& r = result_of(results, c.id);
    for (std::size_t a = 0; a < 3; ++a) {
      const AlgorithmRun& run = r.runs[a];
      nlohmann::json j;
      j["case"] = c.id;
      j["figure"] = c.figure;
      j["role"] = to_string(c.role);
      j["algorithm"] = io::to_string(run.algorithm);
      j["parameter"] = parameter_name(c.parameter);
      j["n_pu"] = c.n_pu;
      j["tau_pu"] = c.tau_pu;
      j["convergence_time_s"] =
          run.metrics.convergence_time_s ? nlohmann::json(*run.metrics.convergence_time_s) : nlohmann::json(nullptr);
      j["steady_state_error_pct"] = run.metrics.steady_state_error_pct;
      j["overshoot_pct"] = run.metrics.overshoot_pct;
      j["wrong_way_pct"] = run.metrics.wrong_way_pct;
      const auto& paper_t = c.paper.convergence_time_s[a];
      j["paper_convergence_time_s"] = paper_t ? nlohmann::json(*paper_t) : nlohmann::json(nullptr);
      out.push_back(j);
    }
  }
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << out.dump(2) << '\n';
}

namespace {

/// "0.79 (within 2×)" for ours against the paper's figure; where the paper gives 0 no ratio exists.
std::string ratio(std::optional<double> ours, std::optional<double> paper) {
  if (!ours || !paper) return "—";
  if (*paper == 0.0) return "paper 0: no ratio";
  const double q = *ours / *paper;
  return fmt(q) + (q >= 0.5 && q <= 2.0 ? " (within 2×)" : " (**not** within 2×)");
}

const char* role_prefix(CaseRole r) {
  switch (r) {
    case CaseRole::kPaper:
      return "";
    case CaseRole::kHypothesis:
      return "*hypothesis:* ";
    case CaseRole::kStudy:
      return "*study:* ";
  }
  return "";
}

void write_tab_comparison(std::ostringstream& md, const std::vector<ReproductionCase>& cases,
                          const std::vector<CaseResult>& results) {
  md << "## tab_comparison: ours beside the paper's (SGA / GNA)\n\n";
  md << "Paper rows run the settings the paper states (tab_psimgains); *hypothesis* rows change a setting to test "
        "an explanation of the paper's numbers; *study* rows show what a setting does. ours/paper is the ratio of "
        "the two figures.\n\n";
  md << "| Case | paper SGA | ours SGA | ours/paper | paper GNA | ours GNA | ours/paper | ours PhyInt |\n"
        "|---|---|---|---|---|---|---|---|\n";
  int within = 0, compared = 0;
  std::string outside;
  for (const ReproductionCase& c : cases) {
    if (!c.paper.convergence_time_s[0]) continue;
    const CaseResult& r = result_of(results, c.id);
    const std::string name = role_prefix(c.role) + c.figure + ": " + c.description;
    // One row per figure: the paper's and ours for SGA and GNA with their ratio, ours for PhyInt.
    using Figures = std::array<std::optional<double>, 3>;
    auto row = [&](const char* what, const Figures& paper, const Figures& ours) {
      md << "| " << name << ", " << what;
      for (std::size_t a = 0; a < 2; ++a)
        md << " | " << fmt(paper[a], 1) << " | " << fmt(ours[a]) << " | " << ratio(ours[a], paper[a]);
      md << " | " << fmt(ours[2]) << " |\n";
    };
    Figures times, errors;
    for (std::size_t a = 0; a < 3; ++a) {
      times[a] = r.runs[a].metrics.convergence_time_s;
      errors[a] = r.runs[a].metrics.steady_state_error_pct;
    }
    row("convergence [s]", c.paper.convergence_time_s, times);
    row("steady-state error [%]", c.paper.steady_state_error_pct, errors);
    if (c.role != CaseRole::kPaper) continue;
    for (std::size_t a = 0; a < 2; ++a) {
      for (const auto& [ours, paper, what] :
           {std::tuple{r.runs[a].metrics.convergence_time_s, c.paper.convergence_time_s[a], "convergence"},
            std::tuple{std::optional(r.runs[a].metrics.steady_state_error_pct), c.paper.steady_state_error_pct[a],
                       "steady-state error"}}) {
        if (!ours || !paper || *paper == 0.0) continue;
        ++compared;
        const double q = *ours / *paper;
        if (q >= 0.5 && q <= 2.0) {
          ++within;
        } else {
          outside += std::string(outside.empty() ? "" : ", ") + c.id + " " + io::to_string(r.runs[a].algorithm) + " " +
                     what + " (" + fmt(q) + ")";
        }
      }
    }
  }
  md << "\nPaper rows: " << within << " of the " << compared
     << " figures with a nonzero paper value are within a factor of two of it; not within: "
     << (outside.empty() ? std::string("none") : outside)
     << ". Where the paper gives 0 or ~0 there is no ratio to take.\n\n";
}

/// The standstill R_s runs beside the scalar recursion of standstill_rs.hpp, and the recursion's bound as a
/// function of the initial error (docs/derivations.md, erratum E5).
void write_standstill_rs(std::ostringstream& md, const std::vector<ReproductionCase>& cases,
                         const std::vector<CaseResult>& results) {
  const ReproductionCase* paper_case = nullptr;
  for (const ReproductionCase& c : cases) {
    if (c.role == CaseRole::kPaper && c.parameter == core::Param::kRs && c.kind == CaseKind::kStartWithError &&
        c.n_pu == 0.0) {
      paper_case = &c;
    }
  }
  if (!paper_case) return;
  StandstillRs gna = standstill_rs_model(*paper_case, core::Algorithm::kGna);
  StandstillRs sga = standstill_rs_model(*paper_case, core::Algorithm::kSga);
  gna.hessian0_rel = sga.hessian0_rel = 0.0;  // the fastest start any R[0] allows
  md << "## R_s at standstill: the scalar recursion (docs/derivations.md, erratum E5)\n\n";
  md << "Time into ±1 % from an initial error r̂s/r_s − 1, with the fastest start any initial Hessian allows "
        "(R[0] → 0), for tab_psimgains' R_s columns (γ_0,rk / γ_0,Lk: GNA "
     << gna.gamma_r << " / " << gna.gamma_L << ", SGA " << sga.gamma_r << " / " << sga.gamma_L
     << "), and the same linearised about the true value:\n\n";
  md << "| initial error | GNA (tab_psimgains) [s] | GNA, linearised [s] | SGA (tab_psimgains) [s] | SGA, linearised [s] |\n"
        "|---|---|---|---|---|\n";
  const double ours = initial_error(*paper_case);
  for (const double e0 : {0.02, 0.04, 0.08, ours}) {
    md << "| " << fmt(100.0 * e0) << " %" << (e0 == ours ? " (ours: the machine 8 % below the offline value)" : "") << " | "
       << fmt(standstill_rs_time_s(gna, e0)) << " | "
       << fmt(linearised_rs_bound_s(gna.gamma_r, gna.gamma_L, gna.sample_period_s, e0)) << " | "
       << fmt(standstill_rs_time_s(sga, e0)) << " | "
       << fmt(linearised_rs_bound_s(sga.gamma_r, sga.gamma_L, sga.sample_period_s, e0)) << " |\n";
  }
  auto pct = [](std::optional<double> v) { return v ? fmt(100.0 * *v) + " %" : std::string("none up to 100 %"); };
  md << "\ntab_comparison's GNA times need, with tab_psimgains' GNA column and the fastest start, an initial error of at "
        "most "
     << pct(standstill_rs_initial_error_for(gna, 8.0)) << " (8 s) or " << pct(standstill_rs_initial_error_for(gna, 4.0))
     << " (4 s).\n\n";
  const StandstillRs sga_ours = standstill_rs_model(*paper_case, core::Algorithm::kSga);
  md << "SGA's settled time constant is T_samp/γ_0,Lk = " << fmt(sga.sample_period_s / sga.gamma_L)
     << " s. With its configured start (R[0]/(i/r_s)² = " << fmt(sga_ours.hessian0_rel) << ") it takes tab_comparison's "
     << "8 s and 6 s into ±1 % from an initial error of " << pct(standstill_rs_initial_error_for(sga_ours, 8.0)) << " and "
     << pct(standstill_rs_initial_error_for(sga_ours, 6.0)) << "; from ours (" << fmt(100.0 * ours) << " %) it is within ±"
     << fmt(100.0 * std::abs(standstill_rs_error_after(sga_ours, ours, 8.0)), 3) << " % after 8 s and ±"
     << fmt(100.0 * std::abs(standstill_rs_error_after(sga_ours, ours, 6.0)), 3) << " % after 6 s.\n\n";
  md << "Our standstill runs beside the recursion with their own initial Hessians:\n\n";
  md << "| case | algorithm | R[0] / (i/r_s)² | recursion [s] | measured [s] |\n|---|---|---|---|---|\n";
  for (const ReproductionCase& c : cases) {
    if (c.parameter != core::Param::kRs || c.kind != CaseKind::kStartWithError || c.n_pu != 0.0) continue;
    const CaseResult& r = result_of(results, c.id);
    for (const core::Algorithm a : {core::Algorithm::kSga, core::Algorithm::kGna}) {
      const StandstillRs m = standstill_rs_model(c, a);
      md << "| " << c.id << " | " << io::to_string(a) << " | " << fmt(m.hessian0_rel, 3) << " | "
         << fmt(standstill_rs_time_s(m, initial_error(c))) << " | "
         << fmt(r.runs[static_cast<std::size_t>(a)].metrics.convergence_time_s) << " |\n";
    }
  }
  md << "\n";
}

}  // namespace

void write_comparison_markdown(const std::string& path, const std::vector<ReproductionCase>& cases,
                               const std::vector<CaseResult>& results) {
  std::ostringstream md;
  md << "# Reproduction of the paper's results (generated by `rpem reproduce`)\n\n";
  md << "Convergence time: from the step (Section V) or the start of adaptation (Section VI) until the estimate "
        "enters and stays within ±1 % of the true value; disturbance cases: until it is back in the band "
        "(0 = never left). Steady-state error: mean over the last second, % of the true value. Overshoot: largest "
        "excursion past the true value, %. Wrong way: largest move from the estimate at the step away from the true value, "
        "% of the true value.\n\n";
  write_tab_comparison(md, cases, results);
  write_standstill_rs(md, cases, results);
  md << "## Every case\n\n";
  md << "| Case | Role | Figure | n [pu] | τ [pu] | Param | SGA conv [s] / sse [%] / os [%] / wrong way [%] | GNA | PhyInt | "
        "Paper says |\n";
  md << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ReproductionCase& c : cases) {
    const CaseResult& r = result_of(results, c.id);
    md << "| " << c.id << " | " << to_string(c.role) << " | " << c.figure << " | " << c.n_pu << " | " << c.tau_pu << " | "
       << parameter_name(c.parameter);
    for (const AlgorithmRun& run : r.runs) {
      md << " | " << fmt(run.metrics.convergence_time_s) << " / " << fmt(run.metrics.steady_state_error_pct) << " / "
         << fmt(run.metrics.overshoot_pct) << " / " << fmt(run.metrics.wrong_way_pct);
    }
    md << " | " << c.paper.qualitative << " |\n";
  }
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << md.str();
}

std::vector<std::string> plot_reproduction(const std::string& dir, const std::vector<ReproductionCase>& cases,
                                           const std::vector<CaseResult>& results) {
  // Group the cases by the paper figure they belong to (the label before the panel).
  std::map<std::string, std::vector<const ReproductionCase*>> figures;
  for (const ReproductionCase& c : cases) {
    const std::string name = c.study_figure.empty() ? c.figure.substr(0, c.figure.find(' ')) : c.study_figure;
    figures[name].push_back(&c);
  }
  std::vector<std::string> written;
  for (const auto& [name, members] : figures) {
    const int panels = static_cast<int>(members.size());
    const int cols = panels > 1 ? 2 : 1, rows = (panels + cols - 1) / cols;
    std::string png = dir;
    png.append("/").append(name).append(".png");
    GnuplotFigure fig(png, 560 * cols, 380 * rows);
    fig.add_line("set multiplot layout " + std::to_string(rows) + "," + std::to_string(cols) + " title " +
                 gp_quote(name + ": estimates of SGA, GNA, PhyInt on the simulated drive (rpem reproduce)") + " noenhanced");
    fig.add_line("set grid; set key bottom right; set xlabel 't [s]'");
    for (const ReproductionCase* c : members) {
      const CaseResult& r = result_of(results, c->id);
      const core::PerUnitBase base = core::PerUnitBase::from_rated(c->scenario.machine.machine.rated);
      const bool psi = c->parameter == core::Param::kPsiM;
      const double scale = psi ? 1.0 / base.flux_Wb : 1.0 / base.impedance_Ohm;
      DataBlock block;
      block.name = c->id;
      block.columns.resize(5);
      const auto& t0 = r.runs[0].trajectory;
      for (std::size_t k = 0; k < t0.size(); ++k) {
        block.columns[0].push_back(t0[k].t_s);
        block.columns[1].push_back(t0[k].truth * scale);
        for (std::size_t a = 0; a < 3; ++a) block.columns[2 + a].push_back(r.runs[a].trajectory[k].estimate * scale);
      }
      fig.add_data(std::move(block));
      // Two lines (figure, then conditions) so neighbouring panels' titles do not run into each other.
      fig.add_line("set title " + gp_quote(c->figure) + ".\"\\n\"." +
                   gp_quote(c->description + " (n = " + fmt(c->n_pu, 3) + ", τ = " + fmt(c->tau_pu) + " pu)") +
                   " noenhanced font ',9'");
      fig.add_line(std::string("set ylabel ") + (psi ? "'ψ_m [pu]'" : "'r_s [pu]'"));
      fig.add_line("plot $" + c->id +
                   " u 1:2 w l lw 2 dt 2 lc 'black' t 'true', '' u 1:3 w l lw 1.5 lc rgb '#1f77b4' t 'SGA', "
                   "'' u 1:4 w l lw 1.5 lc rgb '#d62728' t 'GNA', '' u 1:5 w l lw 1.5 lc rgb '#2ca02c' t 'PhyInt'");
    }
    fig.add_line("unset multiplot");
    fig.render();
    written.push_back(png);
  }
  return written;
}

}  // namespace rpem::analysis
