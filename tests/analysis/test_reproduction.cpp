// The paper's reproduction (all of Sections V and VI, three algorithms) against the committed golden
// results with two-sided bounds: a change in either direction fails, so an "improvement" is noticed
// and reviewed too. Regenerate deliberately with scripts/update-golden.sh.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "rpem/analysis/reproduction.hpp"
#include "rpem/io/machine_config.hpp"
#include "support/temp_file.hpp"

namespace rpem::analysis {
namespace {

struct Golden {
  std::optional<double> convergence_time_s;
  double steady_state_error_pct;
  double overshoot_pct;
};

std::map<std::string, Golden> load_golden() {
  std::ifstream in(test::source_dir() + "/tests/golden/reproduce.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::map<std::string, Golden> g;
  for (const auto& e : j) {
    Golden v;
    if (!e["convergence_time_s"].is_null()) v.convergence_time_s = e["convergence_time_s"].get<double>();
    v.steady_state_error_pct = e["steady_state_error_pct"].get<double>();
    v.overshoot_pct = e["overshoot_pct"].get<double>();
    g[e["case"].get<std::string>() + "/" + e["algorithm"].get<std::string>()] = v;
  }
  return g;
}

class Reproduction : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    cases_ = new std::vector<ReproductionCase>(paper_cases());
    results_ = new std::vector<CaseResult>(cases_->size());
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
      for (std::size_t i; (i = next++) < cases_->size();) (*results_)[i] = run_case((*cases_)[i]);
    };
    std::thread a(worker), b(worker);
    a.join();
    b.join();
  }
  static void TearDownTestSuite() {
    delete cases_;
    delete results_;
  }
  static const AlgorithmRun& run(const std::string& id, core::Algorithm a) {
    for (std::size_t i = 0; i < cases_->size(); ++i) {
      if ((*cases_)[i].id == id) return (*results_)[i].runs[static_cast<std::size_t>(a)];
    }
    throw std::runtime_error("no case " + id);
  }
  static std::vector<ReproductionCase>* cases_;
  static std::vector<CaseResult>* results_;
};
std::vector<ReproductionCase>* Reproduction::cases_ = nullptr;
std::vector<CaseResult>* Reproduction::results_ = nullptr;

TEST_F(Reproduction, MatchesTheGoldenResultsWithinTwoSidedBounds) {
  const auto golden = load_golden();
  ASSERT_EQ(golden.size(), 3 * cases_->size()) << "golden file and case list differ: run scripts/update-golden.sh";
  for (std::size_t i = 0; i < cases_->size(); ++i) {
    for (const AlgorithmRun& r : (*results_)[i].runs) {
      const std::string key = (*cases_)[i].id + "/" + io::to_string(r.algorithm);
      SCOPED_TRACE(key);
      ASSERT_TRUE(golden.count(key));
      const Golden& g = golden.at(key);
      ASSERT_EQ(r.metrics.convergence_time_s.has_value(), g.convergence_time_s.has_value());
      if (g.convergence_time_s) {
        EXPECT_NEAR(*r.metrics.convergence_time_s, *g.convergence_time_s, std::max(0.15, 0.15 * *g.convergence_time_s));
      }
      EXPECT_NEAR(r.metrics.steady_state_error_pct, g.steady_state_error_pct,
                  std::max(0.1, 0.1 * std::abs(g.steady_state_error_pct)));
      EXPECT_NEAR(r.metrics.overshoot_pct, g.overshoot_pct, std::max(0.3, 0.2 * g.overshoot_pct));
    }
  }
}

TEST_F(Reproduction, MatchesTabComparisonWithinAFactorOfTwo) {
  // tab_comparison: ψm ~2 s / ~0.5 s (no load), ~1.5 s / ~1.5 s (0.4 load); R_s 8 s / 8 s (standstill),
  // 6 s / 4 s (0.005 pu) for SGA / GNA.
  struct Row {
    const char* id;
    double sga_s, gna_s;
  };
  for (const Row r : {Row{"VI_psim_a", 2.0, 0.5}, Row{"VI_psim_b", 1.5, 1.5}, Row{"VI_rs_a", 8.0, 8.0},
                      Row{"VI_rs_b", 6.0, 4.0}}) {
    for (auto [algorithm, paper_s] : {std::pair{core::Algorithm::kSga, r.sga_s}, {core::Algorithm::kGna, r.gna_s}}) {
      SCOPED_TRACE(std::string(r.id) + "/" + io::to_string(algorithm));
      const auto& t = run(r.id, algorithm).metrics.convergence_time_s;
      ASSERT_TRUE(t);
      EXPECT_GE(*t, paper_s / 2.0);
      EXPECT_LE(*t, paper_s * 2.0);
    }
  }
}

TEST_F(Reproduction, TabulatedGnaGainsCannotGiveTabComparisonsRsTimes) {
  // docs/reproduction.md: with tab_psimgains' GNA column (γ_0,rk = 6.25e-5, γ_0,Lk = 7.5e-6) the Newton
  // step's rate is at most γ_0,Lk / (1 − (1 − γ_0,rk)^k) per sample whatever R[0]; from 8 % into ±1 %
  // that takes at least 13.9 s, against tab_comparison's 8 s and 4 s.
  for (const char* id : {"VI_rs_a_gna_tabulated", "VI_rs_b_gna_tabulated"}) {
    const auto& t = run(id, core::Algorithm::kGna).metrics.convergence_time_s;
    ASSERT_TRUE(t) << id;
    EXPECT_GE(*t, 13.9) << id;
  }
}

TEST_F(Reproduction, QualitativeFindingsOfThePaper) {
  // GNA with SGA's R_s gains is unstable at −0.05 pu: it runs into the bound of D_M.
  EXPECT_FALSE(run("V_rs_a_gna_on_sga_gains", core::Algorithm::kGna).metrics.convergence_time_s);
  EXPECT_TRUE(run("V_rs_a_gna_on_sga_gains", core::Algorithm::kSga).metrics.convergence_time_s);
  // With its ~10× smaller gain GNA is stable but slower than SGA for R_s.
  for (const char* id : {"V_rs_a", "V_rs_b", "V_rs_c", "V_rs_d"}) {
    EXPECT_GT(*run(id, core::Algorithm::kGna).metrics.convergence_time_s,
              2.0 * *run(id, core::Algorithm::kSga).metrics.convergence_time_s)
        << id;
  }
  // GNA is excited by the speed reversal and the load step; SGA stays within ±1 % throughout.
  for (const char* id : {"VI_psim_c", "VI_psim_d"}) {
    EXPECT_GT(run(id, core::Algorithm::kGna).metrics.overshoot_pct,
              3.0 * run(id, core::Algorithm::kSga).metrics.overshoot_pct)
        << id;
    EXPECT_EQ(*run(id, core::Algorithm::kSga).metrics.convergence_time_s, 0.0) << id;
  }
}

}  // namespace
}  // namespace rpem::analysis
