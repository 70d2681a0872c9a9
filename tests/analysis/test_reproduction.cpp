// The paper's reproduction (all of Sections V and VI, three algorithms) against the committed golden
// results — docs/figures/reproduction/reproduce.json, the very output docs/reproduction.md shows — with
// two-sided bounds: a change in either direction fails, so an "improvement" is noticed and reviewed too.
// Regenerate deliberately with scripts/update-golden.sh. Beside the golden file: tab_comparison's
// figures, each held to what docs/reproduction.md says of it (within a factor of two or not, and why),
// and the standstill R_s runs against the scalar recursion that bounds and predicts them.
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
  double wrong_way_pct;
};

std::map<std::string, Golden> load_golden() {
  const std::string path = test::source_dir() + "/docs/figures/reproduction/reproduce.json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("golden file missing: " + path + " (scripts/update-golden.sh writes it)");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::map<std::string, Golden> g;
  for (const auto& e : j) {
    Golden v;
    if (!e["convergence_time_s"].is_null()) v.convergence_time_s = e["convergence_time_s"].get<double>();
    v.steady_state_error_pct = e["steady_state_error_pct"].get<double>();
    v.overshoot_pct = e["overshoot_pct"].get<double>();
    v.wrong_way_pct = e["wrong_way_pct"].get<double>();
    g[e["case"].get<std::string>() + "/" + e["algorithm"].get<std::string>()] = v;
  }
  return g;
}

class Reproduction : public ::testing::Test {
 public:
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
  static const ReproductionCase& case_of(const std::string& id) {
    for (const ReproductionCase& c : *cases_) {
      if (c.id == id) return c;
    }
    throw std::runtime_error("no case " + id);
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
      EXPECT_NEAR(r.metrics.wrong_way_pct, g.wrong_way_pct, std::max(0.3, 0.2 * g.wrong_way_pct));
    }
  }
}

/// ours / paper for one algorithm's convergence time.
double ratio_to_paper(const std::string& id, core::Algorithm a, double paper_s) {
  const auto& t = Reproduction::run(id, a).metrics.convergence_time_s;
  if (!t) throw std::runtime_error(id + " did not converge");
  return *t / paper_s;
}

TEST_F(Reproduction, TabComparisonFiguresAreWithinAFactorOfTwoExactlyWhereTheDocSaysSo) {
  // tab_comparison (SGA / GNA): ψm ~2 s / ~0.5 s (no load), ~1.5 s / ~1.5 s (0.4 load); R_s 8 s / 8 s
  // (standstill), 6 s / 4 s (0.005 pu). With the paper's settings every ψm time and SGA's R_s times are within
  // a factor of two; GNA's R_s times are not (erratum E5: tab_psimgains' GNA column cannot reach them).
  struct Row {
    const char* id;
    double sga_s, gna_s;
    bool gna_within;
  };
  for (const Row r : {Row{"VI_psim_a", 2.0, 0.5, true}, Row{"VI_psim_b", 1.5, 1.5, true}, Row{"VI_rs_a", 8.0, 8.0, false},
                      Row{"VI_rs_b", 6.0, 4.0, false}}) {
    SCOPED_TRACE(r.id);
    const double sga = ratio_to_paper(r.id, core::Algorithm::kSga, r.sga_s);
    EXPECT_GE(sga, 0.5);
    EXPECT_LE(sga, 2.0);
    const double gna = ratio_to_paper(r.id, core::Algorithm::kGna, r.gna_s);
    if (r.gna_within) {
      EXPECT_GE(gna, 0.5);
      EXPECT_LE(gna, 2.0);
    } else {
      EXPECT_GT(gna, 2.0);
    }
  }
  // The hypothesis rows (GNA given SGA's R_s settings) bring GNA within a factor of two.
  for (auto [id, paper_s] : {std::pair{"VI_rs_a_gna_sga_settings", 8.0}, {"VI_rs_b_gna_sga_settings", 4.0}}) {
    const double gna = ratio_to_paper(id, core::Algorithm::kGna, paper_s);
    EXPECT_GE(gna, 0.5) << id;
    EXPECT_LE(gna, 2.0) << id;
  }
  // Steady-state errors: the paper's −0.5 % (SGA) and +0.5 % (GNA) at no load are not reproduced — the
  // simulated bench has no model error for the estimate to absorb (docs/reproduction.md, difference 4).
  for (const core::Algorithm a : {core::Algorithm::kSga, core::Algorithm::kGna}) {
    EXPECT_LT(std::abs(run("VI_psim_a", a).metrics.steady_state_error_pct), 0.1) << io::to_string(a);
  }
}

TEST_F(Reproduction, StandstillRsRunsFollowTheScalarRecursion) {
  // docs/derivations.md E5: at standstill SGA and GNA reduce to one scalar recursion. Our runs, with their own
  // gains and initial Hessians, must take what it predicts within 10 % (a two-sided check of the derivation).
  for (const char* id : {"VI_rs_a", "VI_rs_a_gna_sga_settings"}) {
    const ReproductionCase& c = case_of(id);
    for (const core::Algorithm a : {core::Algorithm::kSga, core::Algorithm::kGna}) {
      SCOPED_TRACE(std::string(id) + "/" + io::to_string(a));
      const auto predicted = standstill_rs_time_s(standstill_rs_model(c, a), initial_error(c));
      const auto& measured = run(id, a).metrics.convergence_time_s;
      ASSERT_TRUE(predicted && measured);
      EXPECT_NEAR(*measured / *predicted, 1.0, 0.10);
    }
  }
}

TEST_F(Reproduction, TabulatedGnaGainsCannotGiveTabComparisonsRsTimes) {
  // The paper's rows run tab_psimgains' GNA column (γ_0,rk = 6.25e-5, γ_0,Lk = 7.5e-6). From our start no
  // initial Hessian gets the recursion into ±1 % faster than its bound (R[0] → 0) — 13.5 s against
  // tab_comparison's 8 s and 4 s — and the runs, starting from R[0] = I, are slower still.
  for (const char* id : {"VI_rs_a", "VI_rs_b"}) {
    StandstillRs fastest = standstill_rs_model(case_of(id), core::Algorithm::kGna);
    fastest.hessian0_rel = 0.0;
    const auto bound = standstill_rs_time_s(fastest, initial_error(case_of(id)));
    ASSERT_TRUE(bound);
    EXPECT_GT(*bound, 8.0);
    const auto& t = run(id, core::Algorithm::kGna).metrics.convergence_time_s;
    ASSERT_TRUE(t) << id;
    EXPECT_GE(*t, *bound) << id;
  }
}

TEST_F(Reproduction, SgaStartsFasterFromASmallerInitialHessian) {
  // docs/reproduction.md, difference 3: the shipped r[0] = 100 slows SGA's ψm start; from r[0] = 1 the same
  // runs converge at least a third sooner, and at no load then faster than the paper's ~2 s by more than 2×.
  for (const char* panel : {"a", "b"}) {
    const std::string id = std::string("VI_psim_") + panel;
    const double shipped = *run(id, core::Algorithm::kSga).metrics.convergence_time_s;
    const double small = *run(id + "_sga_r0_1", core::Algorithm::kSga).metrics.convergence_time_s;
    EXPECT_LT(small, 0.67 * shipped) << id;
    // GNA and PhyInt do not use SGA's Hessian: their runs are unchanged.
    EXPECT_EQ(*run(id + "_sga_r0_1", core::Algorithm::kGna).metrics.convergence_time_s,
              *run(id, core::Algorithm::kGna).metrics.convergence_time_s);
  }
  EXPECT_LT(ratio_to_paper("VI_psim_a_sga_r0_1", core::Algorithm::kSga, 2.0), 0.5);
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
