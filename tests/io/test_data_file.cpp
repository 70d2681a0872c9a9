// tests/support/data_file.hpp: a test that needs a data file the repository ships fails naming its path
// when the file is missing, instead of passing on nothing (issue 15, item 3).
#include <gtest/gtest.h>

#include <string>

#include "support/data_file.hpp"

namespace rpem {
namespace {

TEST(DataFile, ShippedFileResolvesUnderData) {
  const std::string path = test::data_file("paderborn-motor-temperature/profile_A_every5th.csv");
  EXPECT_EQ(path, test::source_dir() + "/data/paderborn-motor-temperature/profile_A_every5th.csv");
}

TEST(DataFile, MissingFileFailsNamingItsPath) {
  try {
    (void)test::data_file("no-such-set/missing.csv");
    FAIL() << "a missing data file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(test::source_dir() + "/data/no-such-set/missing.csv"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace rpem
