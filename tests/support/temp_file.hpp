#pragma once
// A file in the test's temporary directory, removed when the object goes out of scope.

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

namespace rpem::test {

/// A path in the temporary directory unique to this process: test runs of several checkouts on one machine
/// (or ctest -j) never share a file.
inline std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("rpem_" + std::to_string(::getpid()) + "_" + name);
}

class TempFile {
 public:
  /// Reserves a path; the file is created only if `content` is given (even if empty).
  explicit TempFile(const std::string& name, std::optional<std::string> content = std::nullopt) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = temp_path(std::string(info->test_suite_name()) + "_" + info->name() + "_" + name);
    std::filesystem::create_directories(path_.parent_path());
    if (content) std::ofstream(path_) << *content;
  }
  ~TempFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

/// A whole file as text (empty if it cannot be read).
inline std::string read_file(const std::string& path) {
  std::ifstream f(path);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

/// The repository root (set by CTest; falls back to the source tree layout).
inline std::string source_dir() {
  const char* env = std::getenv("RPEM_SOURCE_DIR");
  return env ? env : std::string(RPEM_TEST_SOURCE_DIR);
}

}  // namespace rpem::test
