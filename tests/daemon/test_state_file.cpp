#include <gtest/gtest.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "rpem/daemon/state_file.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

LoadedState load(const std::string& path) { return load_state_file(path, 3600.0, 0.5, 1.7, 1.0, 4.5); }

TEST(StateFile, WriteThenLoad) {
  test::TempFile f("estimates.json");
  PersistedEstimates e;
  e.psi_m_Wb = 1.1;
  e.r_s_Ohm = 2.4;
  e.written_unix_s = std::time(nullptr);
  ASSERT_EQ(write_state_file(f.path(), e), "");
  EXPECT_FALSE(std::filesystem::exists(f.path() + ".tmp"));
  const LoadedState s = load(f.path());
  EXPECT_EQ(s.status, StateFileStatus::kLoaded);
  EXPECT_DOUBLE_EQ(*s.estimates.psi_m_Wb, 1.1);
  EXPECT_DOUBLE_EQ(*s.estimates.r_s_Ohm, 2.4);
}

TEST(StateFile, OnlyTheConvergedParameter) {
  test::TempFile f("estimates.json");
  PersistedEstimates e;
  e.r_s_Ohm = 2.4;
  e.written_unix_s = std::time(nullptr);
  ASSERT_EQ(write_state_file(f.path(), e), "");
  const LoadedState s = load(f.path());
  EXPECT_EQ(s.status, StateFileStatus::kLoaded);
  EXPECT_FALSE(s.estimates.psi_m_Wb);
}

TEST(StateFile, MissingTooOldImplausibleCorrupt) {
  EXPECT_EQ(load("/nonexistent/estimates.json").status, StateFileStatus::kNone);
  test::TempFile old("old.json");
  PersistedEstimates e;
  e.psi_m_Wb = 1.1;
  e.written_unix_s = std::time(nullptr) - 7200;
  ASSERT_EQ(write_state_file(old.path(), e), "");
  EXPECT_EQ(load(old.path()).status, StateFileStatus::kTooOld);
  test::TempFile odd("odd.json");
  e.psi_m_Wb = 9.0;
  e.written_unix_s = std::time(nullptr);
  ASSERT_EQ(write_state_file(odd.path(), e), "");
  EXPECT_EQ(load(odd.path()).status, StateFileStatus::kImplausible);
  for (const char* text :
       {"{ not json", "[]", "{\"format\": \"rpemd-estimates-1\"}",
        "{\"format\": \"other\", \"psi_m_Wb\": 1.1, \"r_s_Ohm\": null, \"written_unix_s\": 0}",
        "{\"format\": \"rpemd-estimates-1\", \"psi_m_Wb\": \"x\", \"r_s_Ohm\": null, \"written_unix_s\": 1}"}) {
    test::TempFile bad("bad.json", std::string(text));
    const LoadedState s = load(bad.path());
    EXPECT_EQ(s.status, StateFileStatus::kCorrupt) << text;
    EXPECT_NE(s.message.find("corrupt"), std::string::npos);
  }
}

/// A three-node thermal state as the loop reports it (winding 0, magnet 2), under a load.
core::ThermalSnapshot saved_thermal_state() {
  core::ThermalSnapshot t;
  t.nodes = 3, t.winding = 0, t.magnet = 2;
  t.t_C << 96.25, 71.5, 88.125, 0.0;
  t.p_K2.diagonal() << 4.0, 2.5, 9.0, 0.0;
  t.p_K2(0, 2) = t.p_K2(2, 0) = 1.0 / 3.0;  // a value no decimal spells exactly
  t.load.current_sq_A2 = 1.2e4;
  t.load.basis = {0.5, 0.25, 0.75};
  t.load.convection_basis = 0.7;
  t.load.coolant_C = 41.5;
  return t;
}

/// Written now, with ψm where `with_estimates`, beside saved_thermal_state() of age `thermal_age_s`.
PersistedEstimates with_thermal(bool with_estimates, std::int64_t thermal_age_s) {
  PersistedEstimates e;
  if (with_estimates) e.psi_m_Wb = 1.1;
  e.written_unix_s = std::time(nullptr);
  e.thermal = {saved_thermal_state(), e.written_unix_s - thermal_age_s};
  return e;
}

// The thermal fusion's state round-trips exactly (docs/rpemd.md, "Persistence"), alone or beside the estimates.
TEST(StateFile, TheThermalStateRoundTripsExactly) {
  for (const bool with_estimates : {true, false}) {
    SCOPED_TRACE(with_estimates);
    test::TempFile f("estimates.json");
    const PersistedEstimates e = with_thermal(with_estimates, 3);
    ASSERT_EQ(write_state_file(f.path(), e), "");
    const LoadedState s = load(f.path());
    ASSERT_EQ(s.status, StateFileStatus::kLoaded) << s.message;
    EXPECT_EQ(s.estimates.thermal.at_unix_s, e.thermal.at_unix_s);
    const core::ThermalSnapshot& t = s.estimates.thermal.state;
    EXPECT_EQ(t.nodes, 3);
    EXPECT_EQ(t.winding, 0);
    EXPECT_EQ(t.magnet, 2);
    EXPECT_EQ(t.t_C, e.thermal.state.t_C);
    EXPECT_EQ(t.p_K2, e.thermal.state.p_K2);
    EXPECT_EQ(t.load.current_sq_A2, e.thermal.state.load.current_sq_A2);
    EXPECT_EQ(t.load.basis, e.thermal.state.load.basis);
    EXPECT_EQ(t.load.convection_basis, e.thermal.state.load.convection_basis);
    EXPECT_EQ(t.load.coolant_C, e.thermal.state.load.coolant_C);
  }
  // A file an rpemd without the thermal state wrote: loaded, no thermal state.
  test::TempFile older("older.json");
  PersistedEstimates e;
  e.psi_m_Wb = 1.1;
  e.written_unix_s = std::time(nullptr);
  ASSERT_EQ(write_state_file(older.path(), e), "");
  const LoadedState s = load(older.path());
  EXPECT_EQ(s.status, StateFileStatus::kLoaded);
  EXPECT_EQ(s.estimates.thermal.state.nodes, 0);
}

// A thermal state older than max_age_s is left out, saying so (the estimates beside it still load); alone, the file
// is too old.
TEST(StateFile, AThermalStateOlderThanTheLimitIsLeftOut) {
  for (const bool with_estimates : {true, false}) {
    SCOPED_TRACE(with_estimates);
    test::TempFile f("estimates.json");
    const PersistedEstimates e = with_thermal(with_estimates, 4000);
    ASSERT_EQ(write_state_file(f.path(), e), "");
    const LoadedState s = load(f.path());
    EXPECT_EQ(s.status, with_estimates ? StateFileStatus::kLoaded : StateFileStatus::kTooOld);
    EXPECT_EQ(s.estimates.thermal.state.nodes, 0);
    EXPECT_NE(s.message.find("thermal state is 400"), std::string::npos) << s.message;  // 4000 s, or a second more
    EXPECT_NE(s.message.find(" s old (limit 3600 s), left out"), std::string::npos) << s.message;
  }
}

// A thermal section of another shape is a corrupt file; one that cannot be a machine's is implausible — each
// ignored with the reason (the whole file: a half-trusted state is not resumed).
TEST(StateFile, AThermalStateThatIsNotOneIsReportedAndIgnored) {
  const PersistedEstimates e = with_thermal(true, 3);
  test::TempFile good("good.json");
  ASSERT_EQ(write_state_file(good.path(), e), "");
  std::ifstream in(good.path());
  const nlohmann::json written = nlohmann::json::parse(in);
  using Edit = std::function<void(nlohmann::json&)>;
  const std::vector<std::pair<Edit, StateFileStatus>> cases = {
      {[](nlohmann::json& t) { t["t_C"][1] = "hot"; }, StateFileStatus::kCorrupt},
      {[](nlohmann::json& t) { t.erase("load"); }, StateFileStatus::kCorrupt},
      {[](nlohmann::json& t) {
         t["p_K2"][2] = nlohmann::json::array({1.0, 0.0});
       },
       StateFileStatus::kCorrupt},
      {[](nlohmann::json& t) { t["t_C"].push_back(50.0); }, StateFileStatus::kCorrupt},
      {[](nlohmann::json& t) { t["nodes"] = 7; }, StateFileStatus::kCorrupt},
      {[](nlohmann::json& t) { t["load"]["basis"] = nlohmann::json::array({1.0}); }, StateFileStatus::kCorrupt},
      {[](nlohmann::json& t) { t["t_C"][2] = -300.0; }, StateFileStatus::kImplausible},
      {[](nlohmann::json& t) { t["p_K2"][1][1] = -1.0; }, StateFileStatus::kImplausible},
      {[](nlohmann::json& t) { t["p_K2"][0][2] = 2.0; }, StateFileStatus::kImplausible},
      // Symmetric with positive variances, but a correlation above 1 (7² > 4·9): not a covariance.
      {[](nlohmann::json& t) { t["p_K2"][0][2] = t["p_K2"][2][0] = 7.0; }, StateFileStatus::kImplausible},
      {[](nlohmann::json& t) { t["magnet"] = 0; }, StateFileStatus::kImplausible},
      {[](nlohmann::json& t) { t["winding"] = 3; }, StateFileStatus::kImplausible},
      {[](nlohmann::json& t) { t["load"]["current_sq_A2"] = -1.0; }, StateFileStatus::kImplausible},
  };
  for (std::size_t k = 0; k < cases.size(); ++k) {
    SCOPED_TRACE(k);
    nlohmann::json j = written;
    cases[k].first(j["thermal"]);
    test::TempFile bad("bad.json", j.dump());
    const LoadedState s = load(bad.path());
    EXPECT_EQ(s.status, cases[k].second) << s.message;
    EXPECT_NE(s.message.find(bad.path()), std::string::npos);
    EXPECT_NE(s.message.find(cases[k].second == StateFileStatus::kCorrupt ? "corrupt" : "thermal"), std::string::npos)
        << s.message;
  }
}

}  // namespace
}  // namespace rpem::daemon
