#pragma once
// Messages as text, every field alike (field.hpp): the line `rpem listen` prints and the CSV it records.
//   line: "name value" per field, or "label value unit" for a field with a [label] (whose name's unit
//         the label drops); fields separated by a space, groups (the .lcm's comment lines) by " | ";
//         numbers as printf's %.6g, booleans 0 or 1, strings quoted, arrays [a b c];
//   CSV:  one column per number (an array: one per element, name[k]), named by display_name(), values
//         as on the line; strings are shown on the line and not recorded, so every column is a number.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

#include "rpem/schema/field.hpp"

namespace rpem::schema {
namespace detail {

void append_number(std::string& out, double v);
void append_number(std::string& out, std::int64_t v);
void append_quoted(std::string& out, std::string_view text);

template <class T>
void append_value(std::string& out, const T& v) {
  if constexpr (std::is_array_v<T>) {
    out += '[';
    for (std::size_t k = 0; k < std::extent_v<T>; ++k) {
      if (k > 0) out += ' ';
      append_value(out, v[k]);
    }
    out += ']';
  } else if constexpr (std::is_floating_point_v<T>) {
    append_number(out, static_cast<double>(v));
  } else if constexpr (std::is_integral_v<T>) {
    append_number(out, static_cast<std::int64_t>(v));
  } else {
    append_quoted(out, v);
  }
}

template <class Field>
using ValueOf = typename std::remove_cvref_t<Field>::value_type;

}  // namespace detail

/// Every field of `m` but those named in `skip` (shown elsewhere in the caller's own words).
template <class Message>
[[nodiscard]] std::string format_fields(const Message& m, std::span<const std::string_view> skip = {}) {
  std::string out;
  std::string_view group;
  bool first = true;
  for_each_field<Message>([&](const auto& field) {
    const FieldInfo& f = field.info;
    for (std::string_view name : skip) {
      if (name == f.name) return;
    }
    if (!first) out += f.group != group ? " | " : " ";
    first = false;
    group = f.group;
    out += display_name(f);
    out += ' ';
    detail::append_value(out, m.*field.member);
    if (!f.label.empty() && !f.unit.empty()) {
      out += ' ';
      out += f.unit;
    }
  });
  return out;
}

/// The CSV columns of `Message`, comma-separated (no newline).
template <class Message>
[[nodiscard]] std::string csv_header() {
  std::string out;
  for_each_field<Message>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (kMirrored<Field>) {
      using T = detail::ValueOf<Field>;
      const std::string_view name = display_name(field.info);
      const std::size_t columns = std::is_array_v<T> ? std::extent_v<T> : 1;
      for (std::size_t k = 0; k < columns; ++k) {
        if (!out.empty()) out += ',';
        out += name;
        if constexpr (std::is_array_v<T>) out += '[' + std::to_string(k) + ']';
      }
    }
  });
  return out;
}

/// One CSV row of `m`: its columns as csv_header<Message>() names them (no newline).
template <class Message>
[[nodiscard]] std::string csv_row(const Message& m) {
  std::string out;
  bool first = true;
  for_each_field<Message>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (kMirrored<Field>) {
      using T = detail::ValueOf<Field>;
      const auto& v = m.*field.member;
      if constexpr (std::is_array_v<T>) {
        for (const auto& element : v) {
          if (!first) out += ',';
          first = false;
          detail::append_value(out, element);
        }
      } else {
        if (!first) out += ',';
        first = false;
        detail::append_value(out, v);
      }
    }
  });
  return out;
}

}  // namespace rpem::schema
