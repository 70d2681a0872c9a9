#pragma once
// Strict YAML mapping reader: every value is checked for type and range where it is read, and
// keys nobody read are rejected by finish(). Errors carry file:line:column and the dotted key path.

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rpem/io/errors.hpp"

namespace rpem::io {

class YamlMap {
 public:
  /// Parses a whole file; the root must be a mapping.
  static YamlMap load_file(const std::string& path);
  /// Parses text (embedded defaults); `name` stands in for the file name in messages.
  static YamlMap load_string(const std::string& text, const std::string& name);

  YamlMap(const YAML::Node& node, std::string file, std::string path);

  [[nodiscard]] bool has(const std::string& key) const;

  /// Numbers in [lo, hi]; required unless a default is given.
  [[nodiscard]] double number(const std::string& key, double lo, double hi);
  [[nodiscard]] double number_or(const std::string& key, double fallback, double lo, double hi);
  /// Decimal, or hexadecimal with a 0x prefix.
  [[nodiscard]] long integer(const std::string& key, long lo, long hi);
  [[nodiscard]] long integer_or(const std::string& key, long fallback, long lo, long hi);
  [[nodiscard]] bool boolean_or(const std::string& key, bool fallback);
  [[nodiscard]] std::string text(const std::string& key);
  [[nodiscard]] std::string text_or(const std::string& key, const std::string& fallback);
  /// A string that must be one of `choices`.
  [[nodiscard]] std::string choice(const std::string& key, std::initializer_list<const char*> choices);
  [[nodiscard]] std::string choice_or(const std::string& key, const std::string& fallback,
                                      std::initializer_list<const char*> choices);
  /// A sequence of exactly `n` numbers in [lo, hi] (n = 0: any length ≥ 1).
  [[nodiscard]] std::vector<double> numbers(const std::string& key, std::size_t n, double lo, double hi);
  /// [min, max] with lo ≤ min < max ≤ hi.
  [[nodiscard]] std::pair<double, double> interval(const std::string& key, double lo, double hi);

  [[nodiscard]] YamlMap map(const std::string& key);
  [[nodiscard]] std::optional<YamlMap> optional_map(const std::string& key);
  /// A sequence of mappings.
  [[nodiscard]] std::vector<YamlMap> maps(const std::string& key);

  /// Rejects every key that was not read. Call after reading a mapping.
  void finish() const;

  /// Error at this mapping, or at `key` inside it.
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;

  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  [[nodiscard]] YAML::Node get(const std::string& key);
  [[nodiscard]] std::string field(const std::string& key) const;
  [[noreturn]] void fail_at(const YAML::Node& node, const std::string& key, const std::string& reason) const;
  [[nodiscard]] double as_number(const YAML::Node& n, const std::string& key, double lo, double hi) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace rpem::io
