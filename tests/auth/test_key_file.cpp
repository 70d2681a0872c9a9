// Key files: the format, the owner-only permission check, generation.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "rpem/auth/key_file.hpp"
#include "support/temp_file.hpp"

namespace rpem::auth {
namespace {

const std::string kText = "rpem-key-1 7 000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n";

TEST(KeyFile, ParsesAndFormatsTheOneLine) {
  const Key k = parse_key(kText, "t");
  EXPECT_EQ(k.id(), 7);
  for (std::size_t i = 0; i < k.bytes().size(); ++i) EXPECT_EQ(k.bytes()[i], i);
  EXPECT_EQ(format_key(k), kText);
}

TEST(KeyFile, RefusesAnythingElseNamingTheFile) {
  for (const std::string& bad :
       {std::string(""), std::string("rpem-key-1 7"), "rpem-key-2 7 " + kText.substr(13), "rpem-key-1 0 " + kText.substr(13),
        "rpem-key-1 x " + kText.substr(13), "rpem-key-1 2147483648 " + kText.substr(13),
        kText.substr(0, kText.size() - 3) + "\n", kText.substr(0, kText.size() - 2) + "g\n", kText + "more\n"}) {
    try {
      (void)parse_key(bad, "keys/command.key");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const KeyError& e) {
      EXPECT_NE(std::string(e.what()).find("keys/command.key"), std::string::npos);
    }
  }
}

TEST(KeyFile, OnlyTheOwnerMayReadIt) {
  test::TempFile f("command.key", kText);
  for (const mode_t mode : {0640, 0604, 0620, 0644}) {
    ASSERT_EQ(::chmod(f.path().c_str(), mode), 0);
    try {
      (void)load_key_file(f.path());
      ADD_FAILURE() << "accepted mode " << std::oct << mode;
    } catch (const KeyError& e) {
      EXPECT_NE(std::string(e.what()).find("chmod 600"), std::string::npos) << e.what();
    }
  }
  for (const mode_t mode : {0600, 0400}) {
    ASSERT_EQ(::chmod(f.path().c_str(), mode), 0);
    EXPECT_EQ(load_key_file(f.path()).id(), 7);
  }
  EXPECT_THROW((void)load_key_file(f.path() + ".missing"), KeyError);
}

TEST(KeyFile, GeneratedKeysAreWrittenOwnerOnlyAndReadBack) {
  test::TempFile f("generated.key");
  const Key a = generate_key(12), b = generate_key(12);
  EXPECT_FALSE(std::ranges::equal(a.bytes(), b.bytes()));
  write_key_file(f.path(), a);
  EXPECT_EQ(std::filesystem::status(f.path()).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  const Key back = load_key_file(f.path());
  EXPECT_EQ(back.id(), 12);
  EXPECT_TRUE(std::ranges::equal(back.bytes(), a.bytes()));
  EXPECT_THROW(write_key_file(f.path(), b), KeyError);  // never replaces a key
}

}  // namespace
}  // namespace rpem::auth
