// `rpem reproduce --out DIR` as a user runs it on a fresh clone: every output the issue names is
// written, reproduce.json carries the documented keys for every case and algorithm, and its numbers are
// those the library computes (tests/analysis/test_reproduction.cpp holds them to the golden file).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

namespace fs = std::filesystem;

TEST(CliReproduce, WritesThePlotsTheTableAndReproduceJson) {
  const fs::path dir = test::temp_path("cli_reproduce");
  fs::remove_all(dir);
  const test::ProcessResult r = test::run_command(test::binary_dir() + "/tools/rpem reproduce --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;

  for (const char* png : {"fig_psim_adapt.png", "fig_rs_adapt.png", "Fig_lab_psim.png", "Fig_Labrs.png",
                          "gna_rs_gain_study.png", "sga_initial_hessian_study.png"}) {
    SCOPED_TRACE(png);
    ASSERT_TRUE(fs::exists(dir / png));
    const std::string bytes = test::read_file((dir / png).string());
    ASSERT_GT(bytes.size(), 10'000U);  // a rendered chart, not an empty canvas
    EXPECT_EQ(bytes.substr(1, 3), "PNG");
  }
  const std::string table = test::read_file((dir / "comparison.md").string());
  EXPECT_NE(table.find("## tab_comparison"), std::string::npos);
  EXPECT_NE(table.find("| Fig_Labrs (a): bench, standstill, 0.4 pu load, convergence [s] | 8.0 |"), std::string::npos);
  EXPECT_NE(table.find("## R_s at standstill: the scalar recursion"), std::string::npos);

  const nlohmann::json j = nlohmann::json::parse(test::read_file((dir / "reproduce.json").string()));
  ASSERT_TRUE(j.is_array());
  std::set<std::string> cases;
  std::map<std::string, int> per_algorithm;
  for (const auto& e : j) {
    for (const char* key : {"case", "role", "algorithm", "parameter", "n_pu", "tau_pu", "convergence_time_s",
                            "steady_state_error_pct", "overshoot_pct", "wrong_way_pct"}) {
      ASSERT_TRUE(e.contains(key)) << key << " in " << e.dump();
    }
    const std::string algorithm = e["algorithm"].get<std::string>();
    ASSERT_TRUE(algorithm == "sga" || algorithm == "gna" || algorithm == "phyint") << algorithm;
    const std::string parameter = e["parameter"].get<std::string>();
    ASSERT_TRUE(parameter == "psi_m" || parameter == "r_s") << parameter;
    const std::string role = e["role"].get<std::string>();
    ASSERT_TRUE(role == "paper" || role == "hypothesis" || role == "study") << role;
    cases.insert(e["case"].get<std::string>());
    ++per_algorithm[algorithm];
  }
  // Section V: 4 + 4 panels and the GNA gain study; Section VI: 4 + 4 panels, two hypothesis rows (GNA with
  // SGA's R_s settings) and two studies (SGA from r[0] = 1).
  EXPECT_EQ(cases.size(), 21U);
  for (const auto& [algorithm, n] : per_algorithm) EXPECT_EQ(n, 21) << algorithm;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rpem
