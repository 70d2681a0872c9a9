#include "rpem/io/yaml_map.hpp"
#include "rpem/io/number_text.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>
#include <vector>

namespace rpem::io {
namespace {

std::string describe_range(double lo, double hi) {
  std::ostringstream s;
  s << "[" << lo << ", " << hi << "]";
  return s.str();
}

/// The edit distance between two keys (insertions, deletions, substitutions; Levenshtein).
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

/// Whether `s` is one of YAML 1.2's non-finite floats: [-+]?.inf, .nan, in any case.
bool yaml_non_finite(std::string_view s) {
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  if (s.size() != 4 || s.front() != '.') return false;
  std::string lower(s.substr(1));
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower == "nan" || lower == "inf";
}

/// YAML notices a bracket or a quote left open only at a later token, often a later line's first: where the error
/// stands at a line's start and the line with content before it leaves a `[`, `{` or `"` open, that line is named.
std::string line_before_hint(const std::string& text, int error_line, int error_column) {
  if (error_line <= 0) return "";
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const auto at = static_cast<std::size_t>(error_line);
  if (at < lines.size() && static_cast<std::size_t>(error_column) > lines[at].find_first_not_of(' ')) return "";
  for (std::size_t k = std::min(at, lines.size()); k-- > 0;) {
    const std::string& line = lines[k];
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::string content = line.substr(0, line.find(" #"));
    content.erase(content.find_last_not_of(" \t\r") + 1);
    const auto count = [&](char c) { return std::count(content.begin(), content.end(), c); };
    if (count('[') <= count(']') && count('{') <= count('}') && count('"') % 2 == 0) return "";
    return " (YAML notices it only here: line " + std::to_string(k + 1) + " leaves a bracket or a quote open, `" +
           content.substr(first, 60) + "`)";
  }
  return "";
}

}  // namespace

YamlMap YamlMap::load_file(const std::string& path) {
  // Read here rather than by YAML::LoadFile: a directory opens and then fails on the first read, and
  // yaml-cpp's stream then throws std::ios_base::failure and leaks its buffer (found by fuzz_scenario).
  std::error_code ec;  // a name too long or a loop of links: not a directory, and the open below fails
  if (std::filesystem::is_directory(path, ec)) throw ConfigError(path, 0, 0, "", "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, 0, 0, "", "cannot open file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ConfigError(path, 0, 0, "", "cannot read file");
  return load_string(text.str(), path);
}

YamlMap YamlMap::load_string(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(name, static_cast<std::size_t>(e.mark.line + 1), static_cast<std::size_t>(e.mark.column + 1), "",
                      "YAML syntax: " + e.msg + line_before_hint(text, e.mark.line, e.mark.column));
  }
  if (!root.IsMap()) throw ConfigError(name, 1, 1, "", "the document must be a mapping");
  return YamlMap(root, name, "");
}

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string path)
    : node_(node), file_(std::move(file)), path_(std::move(path)) {
  // A key given twice: yaml-cpp keeps both and a lookup finds the first, so the second would be ignored silently.
  if (!node_.IsMap()) return;
  std::set<std::string> keys;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) continue;  // a complex key: no reader asks for one, finish() names it
    const std::string key = entry.first.Scalar();
    if (!keys.insert(key).second) fail_at(entry.first, key, "given twice in this mapping (the first would be used)");
  }
}

std::string YamlMap::field(const std::string& key) const {
  if (key.empty()) return path_;
  return path_.empty() ? key : path_ + "." + key;
}

void YamlMap::fail_at(const YAML::Node& node, const std::string& key, const std::string& reason) const {
  const YAML::Mark mark = node.Mark();
  const bool valid = mark.line >= 0;
  throw ConfigError(file_, valid ? static_cast<std::size_t>(mark.line + 1) : 0,
                    valid ? static_cast<std::size_t>(mark.column + 1) : 0, field(key), reason);
}

void YamlMap::fail(const std::string& key, const std::string& reason) const {
  if (!key.empty() && node_[key]) fail_at(node_[key], key, reason);
  fail_at(node_, key, reason);
}

bool YamlMap::has(const std::string& key) const { return static_cast<bool>(node_[key]); }

YAML::Node YamlMap::get(const std::string& key) {
  used_.insert(key);
  const YAML::Node n = node_[key];
  if (!n) {
    // A key within an edit per four characters is a misspelling of this one (finish() would name it as unknown,
    // but only after this); `min` for `max` is not.
    const std::size_t typo = std::max<std::size_t>(1, key.size() / 4);
    for (const auto& entry : node_) {
      if (!entry.first.IsScalar() || edit_distance(entry.first.Scalar(), key) > typo) continue;
      fail_at(entry.first, key, "required key is missing; `" + entry.first.Scalar() + "` is given: misspelt?");
    }
    fail_at(node_, key, "required key is missing");
  }
  return n;
}

double YamlMap::as_number(const YAML::Node& n, const std::string& key, double lo, double hi) const {
  if (!n.IsScalar()) fail_at(n, key, "expected a number");
  const std::string& s = n.Scalar();
  // YAML's own spellings of the non-finite (.nan, .inf, -.Inf, …) read as what they are, as C's `nan` and `inf` do.
  if (yaml_non_finite(s)) fail_at(n, key, "'" + s + "' is not finite");
  const NumberText read = read_number(s);
  if (read.kind != NumberText::Kind::kNumber) fail_at(n, key, read.reason(s));
  const double v = read.value;
  if (!std::isfinite(v)) fail_at(n, key, "'" + s + "' is not finite");
  if (v < lo || v > hi) fail_at(n, key, s + " is outside " + describe_range(lo, hi));
  return v;
}

double YamlMap::number(const std::string& key, double lo, double hi) { return as_number(get(key), key, lo, hi); }

double YamlMap::number_or(const std::string& key, double fallback, double lo, double hi) {
  if (!has(key)) {
    used_.insert(key);
    return fallback;
  }
  return number(key, lo, hi);
}

long YamlMap::integer(const std::string& key, long lo, long hi) {
  const YAML::Node n = get(key);
  if (!n.IsScalar()) fail_at(n, key, "expected an integer");
  const std::string& s = n.Scalar();
  long v = 0;
  const bool hex = s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');  // 0x181: CAN ids
  const char* first = s.data() + (hex ? 2 : 0);
  const auto [end, ec] = std::from_chars(first, s.data() + s.size(), v, hex ? 16 : 10);
  if (ec != std::errc() || end != s.data() + s.size()) fail_at(n, key, "'" + s + "' is not an integer");
  if (v < lo || v > hi)
    fail_at(n, key, s + " is outside " + describe_range(static_cast<double>(lo), static_cast<double>(hi)));
  return v;
}

long YamlMap::integer_or(const std::string& key, long fallback, long lo, long hi) {
  if (!has(key)) {
    used_.insert(key);
    return fallback;
  }
  return integer(key, lo, hi);
}

bool YamlMap::boolean_or(const std::string& key, bool fallback) {
  if (!has(key)) {
    used_.insert(key);
    return fallback;
  }
  const YAML::Node n = get(key);
  if (n.IsScalar()) {
    const std::string& s = n.Scalar();
    if (s == "true") return true;
    if (s == "false") return false;
  }
  fail_at(n, key, "expected true or false");
}

std::string YamlMap::text(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsScalar()) fail_at(n, key, "expected a string");
  return n.Scalar();
}

std::string YamlMap::text_or(const std::string& key, const std::string& fallback) {
  if (!has(key)) {
    used_.insert(key);
    return fallback;
  }
  return text(key);
}

std::string YamlMap::choice(const std::string& key, std::initializer_list<const char*> choices) {
  std::string v = text(key);  // not const: returned by move
  std::string list;
  for (const char* c : choices) {
    if (v == c) return v;
    list += list.empty() ? c : std::string(", ") + c;
  }
  fail_at(node_[key], key, "'" + v + "' is not one of: " + list);
}

std::string YamlMap::choice_or(const std::string& key, const std::string& fallback,
                               std::initializer_list<const char*> choices) {
  if (!has(key)) {
    used_.insert(key);
    return fallback;
  }
  return choice(key, choices);
}

std::vector<double> YamlMap::numbers(const std::string& key, std::size_t n, double lo, double hi) {
  const YAML::Node seq = get(key);
  if (!seq.IsSequence() || seq.size() == 0) fail_at(seq, key, "expected a list of numbers");
  if (n > 0 && seq.size() != n)
    fail_at(seq, key, "expected " + std::to_string(n) + " numbers, got " + std::to_string(seq.size()));
  std::vector<double> out;
  for (std::size_t i = 0; i < seq.size(); ++i) out.push_back(as_number(seq[i], key + "[" + std::to_string(i) + "]", lo, hi));
  return out;
}

std::pair<double, double> YamlMap::interval(const std::string& key, double lo, double hi) {
  const std::vector<double> v = numbers(key, 2, lo, hi);
  if (!(v[0] < v[1])) fail_at(node_[key], key, "expected [min, max] with min < max");
  return {v[0], v[1]};
}

YamlMap YamlMap::map(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsMap()) fail_at(n, key, "expected a mapping");
  return YamlMap(n, file_, field(key));
}

std::optional<YamlMap> YamlMap::optional_map(const std::string& key) {
  if (!has(key)) {
    used_.insert(key);
    return std::nullopt;
  }
  return map(key);
}

std::vector<YamlMap> YamlMap::maps(const std::string& key) {
  const YAML::Node seq = get(key);
  if (!seq.IsSequence()) fail_at(seq, key, "expected a list");
  std::vector<YamlMap> out;
  for (std::size_t i = 0; i < seq.size(); ++i) {
    if (!seq[i].IsMap()) fail_at(seq[i], key + "[" + std::to_string(i) + "]", "expected a mapping");
    out.emplace_back(seq[i], file_, field(key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

void YamlMap::finish() const {
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    // A complex key (`? [a, b]`, `? {a: 1}`) names nothing we read; yaml-cpp would throw on converting it.
    if (!it->first.IsScalar()) fail_at(it->first, "", "a key must be a name, not a list or mapping");
    const std::string key = it->first.Scalar();
    if (used_.count(key) == 0) fail_at(it->first, key, "unknown key");
  }
}

}  // namespace rpem::io
