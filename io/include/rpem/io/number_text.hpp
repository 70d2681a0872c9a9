#pragma once
// Reading a number from a cell or a value as people and programs write it: std::from_chars's form, and also with a
// leading '+' (what C's strtod and spreadsheets accept), and telling a number beyond a double's range from text that is
// no number at all. One place, for every reader of logs and configurations.

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

namespace rpem::io {

struct NumberText {
  enum class Kind { kNumber, kNotANumber, kOutOfRange };
  Kind kind = Kind::kNotANumber;
  double value = 0.0;  ///< kNumber: the value (a magnitude below the smallest subnormal reads as 0, as strtod does)
  /// The reason to give for `text` when kind is not kNumber.
  [[nodiscard]] std::string reason(std::string_view text) const {
    const std::string quoted = "'" + std::string(text) + "'";
    return kind == Kind::kOutOfRange ? quoted + " is beyond the range of a double (±1.8e308)" : quoted + " is not a number";
  }
};

[[nodiscard]] inline NumberText read_number(std::string_view s) {
  if (s.size() > 1 && s.front() == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || end != s.data() + s.size()) return {};
  if (ec == std::errc::result_out_of_range) {
    // from_chars says so both above the largest double and below the smallest subnormal: strtod tells which.
    const double approx = std::strtod(std::string(s).c_str(), nullptr);
    if (std::isinf(approx)) return {NumberText::Kind::kOutOfRange, 0.0};
    return {NumberText::Kind::kNumber, approx};
  }
  if (ec != std::errc()) return {};
  return {NumberText::Kind::kNumber, v};
}

/// Whether `s` reads as a number (read_number's kNumber).
[[nodiscard]] inline bool is_number_text(std::string_view s) { return read_number(s).kind == NumberText::Kind::kNumber; }

}  // namespace rpem::io
