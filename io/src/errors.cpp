#include "rpem/io/errors.hpp"

namespace rpem::io {
namespace {

std::string format(const std::string& file, std::size_t line, std::size_t column, const std::string& field,
                   const std::string& reason) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  if (column > 0) s += ":" + std::to_string(column);
  s += ": ";
  if (!field.empty()) s += field + ": ";
  return s + reason;
}

}  // namespace

InputError::InputError(const std::string& file, std::size_t line, std::size_t column, const std::string& field,
                       const std::string& reason)
    : std::runtime_error(format(file, line, column, field, reason)),
      file_(file),
      line_(line),
      field_(field),
      reason_(reason) {}

}  // namespace rpem::io
