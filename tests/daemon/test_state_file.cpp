#include <gtest/gtest.h>

#include <ctime>
#include <filesystem>
#include <fstream>

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

}  // namespace
}  // namespace rpem::daemon
