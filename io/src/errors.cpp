#include "rpem/io/errors.hpp"

#include <filesystem>
#include <system_error>

namespace rpem::io {
namespace {

/// Control characters a file's cell may hold (a NUL would end the message where what() is printed) as \xNN.
std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7F) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 0xF];
    } else {
      out += c;
    }
  }
  return out;
}

std::string format(const std::string& file, std::size_t line, std::size_t column, const std::string& field,
                   const std::string& reason) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  if (column > 0) s += ":" + std::to_string(column);
  s += ": ";
  if (!field.empty()) s += field + ": ";
  return printable(s + reason);
}

}  // namespace

InputError::InputError(const std::string& file, std::size_t line, std::size_t column, const std::string& field,
                       const std::string& reason)
    : std::runtime_error(format(file, line, column, field, reason)),
      file_(file),
      line_(line),
      field_(field),
      reason_(reason) {}

void create_output_directory(const std::string& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw InputError(directory, 0, 0, "", "cannot create the output directory: " + ec.message());
  if (!std::filesystem::is_directory(directory, ec)) throw InputError(directory, 0, 0, "", "is not a directory");
}

void require_output_directory(const std::string& file) {
  const std::filesystem::path dir = std::filesystem::path(file).parent_path();
  std::error_code ec;
  if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) {
    throw InputError(file, 0, 0, "", "cannot create file: no directory " + dir.string() + " (create it first)");
  }
}

}  // namespace rpem::io
