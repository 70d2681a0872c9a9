#pragma once
// The measured data the repository carries (data/, one folder per data set with its README and licence).

#include <filesystem>
#include <stdexcept>
#include <string>

#include "support/temp_file.hpp"

namespace rpem::test {

/// data/<relative>: its path, or an exception naming that path if the file is missing, so a test that needs
/// shipped data fails loudly instead of passing on nothing.
inline std::string data_file(const std::string& relative) {
  const std::string path = source_dir() + "/data/" + relative;
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("shipped data file missing: " + path + " (data/README.md lists what the repository carries)");
  }
  return path;
}

}  // namespace rpem::test
