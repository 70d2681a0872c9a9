#pragma once
// A message's fields as data: lcm_types/schema_gen.py writes, from each .lcm file, a specialisation of
// Schema<Message> (rpem/mirror/<struct>.hpp) listing every field — name, LCM type, label, unit, group,
// documentation, a member pointer into lcm-gen's class and, for all but strings, one into the heap-free
// mirror. What is done to every field is written once, here and in text.hpp, over that list: copying a
// mirror into the LCM message, printing, CSV columns. Adding a field to a .lcm file is then all it takes
// for it to reach all three (docs/architecture.md, "One definition per message").

#include <algorithm>
#include <array>
#include <cstddef>
#include <iterator>
#include <string_view>
#include <tuple>
#include <type_traits>

namespace rpem::schema {

/// What the .lcm file says of a field.
struct FieldInfo {
  std::string_view name;      ///< as declared
  std::string_view lcm_type;  ///< "int64_t", "boolean", "string", "double[3]" …
  std::string_view label;     ///< the comment's leading [label]: the short name `rpem listen` shows; "" none
  std::string_view unit;      ///< from the name's suffix ("Wb" for psi_m_Wb); "" none
  std::string_view group;     ///< the title of the comment line that opened the field's group; "" before any
  std::string_view doc;       ///< the field's trailing comment, without the label
};

/// What `rpem listen` and its CSV call a field: its label, else its name.
[[nodiscard]] constexpr std::string_view display_name(const FieldInfo& f) noexcept {
  return f.label.empty() ? f.name : f.label;
}

/// A field of the LCM message `Message` with no counterpart in the mirror (a string: its sender spells it).
template <class Message, class T>
struct SpelledField {
  using value_type = T;
  FieldInfo info;
  T Message::*member;
};

/// A field of the LCM message and its counterpart in the mirror (`U` may differ from `T`: bool for LCM's
/// boolean, which lcm-gen declares int8_t; std::array for a fixed array).
template <class Message, class T, class Mirror, class U>
struct MirroredField {
  using value_type = T;
  FieldInfo info;
  T Message::*member;
  U Mirror::*mirror;
};

template <class Message, class T>
constexpr SpelledField<Message, T> spelled(FieldInfo info, T Message::*member) {
  return {info, member};
}
template <class Message, class T, class Mirror, class U>
constexpr MirroredField<Message, T, Mirror, U> mirrored(FieldInfo info, T Message::*member, U Mirror::*mirror) {
  return {info, member, mirror};
}

/// Specialised for each LCM message by its generated header: Message, Mirror, kName, kAuthenticated
/// (key_id and mac, the last two fields, are left to auth/ and are not in kFields), kFields.
template <class Message>
struct Schema;

template <class Field>
inline constexpr bool kMirrored = requires(const Field& f) {
  f.mirror;
};

/// Calls `f(field)` for every field of `Message` in declaration order (the authentication fields aside).
template <class Message, class F>
constexpr void for_each_field(F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, Schema<Message>::kFields);
}

/// How many fields `Message` has (the authentication fields aside).
template <class Message>
inline constexpr std::size_t kFieldCount = std::tuple_size_v<std::remove_cvref_t<decltype(Schema<Message>::kFields)>>;

/// Whether `Message` has a field of every name in `names` (checked at compile time where a printer names
/// the fields it shows in its own words).
template <class Message, class Names>
[[nodiscard]] constexpr bool has_fields(const Names& names) {
  return std::all_of(std::begin(names), std::end(names), [](std::string_view name) {
    bool found = false;
    for_each_field<Message>([&](const auto& field) { found = found || field.info.name == name; });
    return found;
  });
}

/// How many fields of `Message` the mirror does not carry (its strings).
template <class Message>
[[nodiscard]] constexpr std::size_t spelled_count() {
  std::size_t n = 0;
  for_each_field<Message>([&](const auto& field) { n += kMirrored<std::remove_cvref_t<decltype(field)>> ? 0 : 1; });
  return n;
}

/// Copies every field of the mirror `from` into the LCM message `to`. Strings and the authentication
/// fields are the caller's. `from` may be a struct derived from the mirror (a report with extras).
template <class Mirror>
constexpr void copy(const Mirror& from, typename Mirror::Message& to) noexcept {
  for_each_field<typename Mirror::Message>([&](const auto& field) {
    if constexpr (kMirrored<std::remove_cvref_t<decltype(field)>>) {
      auto& out = to.*field.member;
      const auto& in = from.*field.mirror;
      if constexpr (std::is_array_v<std::remove_reference_t<decltype(out)>>) {
        std::copy(std::begin(in), std::end(in), std::begin(out));
      } else {
        out = static_cast<std::remove_reference_t<decltype(out)>>(in);
      }
    }
  });
}

}  // namespace rpem::schema
