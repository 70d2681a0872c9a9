#pragma once
// Writes what `rpem reproduce` produces: reproduce.json, comparison.md (tab_comparison style, our
// numbers beside the paper's) and the figures fig_psim_adapt.png, fig_rs_adapt.png,
// Fig_lab_psim.png, Fig_Labrs.png (plus the gain study).

#include <string>
#include <vector>

#include "rpem/analysis/reproduction.hpp"

namespace rpem::analysis {

void write_reproduce_json(const std::string& path, const std::vector<ReproductionCase>& cases,
                          const std::vector<CaseResult>& results);
void write_comparison_markdown(const std::string& path, const std::vector<ReproductionCase>& cases,
                               const std::vector<CaseResult>& results);
/// One PNG per paper figure; returns the files written.
std::vector<std::string> plot_reproduction(const std::string& dir, const std::vector<ReproductionCase>& cases,
                                           const std::vector<CaseResult>& results);

}  // namespace rpem::analysis
