#pragma once
// Errors raised while reading files (start-up and offline only; never on the real-time path).
// Every message names the file, the line and the field, e.g.
//   config/paper-ipmsm.yaml:12:5: estimator.gains.sga.psi_m.gain: 2 is outside [0, 1]

#include <cstddef>
#include <stdexcept>
#include <string>

namespace rpem::io {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, std::size_t line, std::size_t column, const std::string& field,
             const std::string& reason);
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] std::size_t line() const noexcept { return line_; }
  [[nodiscard]] const std::string& field() const noexcept { return field_; }
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string field_;
  std::string reason_;
};

/// Configuration problems (bad YAML, unknown keys, values out of range). The daemon exits 78 on these.
class ConfigError : public InputError {
  using InputError::InputError;
};

/// A data file's content (a cell, a row, a header) is wrong, where the file itself could be read: tools exit 65.
class DataError : public InputError {
  using InputError::InputError;
};

/// Drive-log CSV problems.
class DriveLogError : public DataError {
  using DataError::DataError;
};

/// Creates `directory` (and its parents) for a tool's output; InputError naming it and why where it cannot be (a
/// file in its place, no permission).
void create_output_directory(const std::string& directory);

/// InputError naming `file` where the directory it is to be written in does not exist: said before a command's
/// work, not after it (a tool creates no parents for a file).
void require_output_directory(const std::string& file);

}  // namespace rpem::io
