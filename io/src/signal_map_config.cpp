#include "rpem/io/signal_map_config.hpp"

#include <limits>

#include "rpem/io/yaml_map.hpp"

namespace rpem::io {
namespace {

can::SignalSpec read_signal(YamlMap m) {
  can::SignalSpec s;
  const std::string field = m.text("field");
  if (!can::parse_field(field, s.field)) m.fail("field", "unknown field '" + field + "' (docs/sources.md lists them)");
  s.start_bit = static_cast<int>(m.integer("start_bit", 0, 511));
  s.length = static_cast<int>(m.integer("length", 1, 64));
  s.big_endian = m.choice_or("byte_order", "little_endian", {"little_endian", "big_endian"}) == "big_endian";
  // DBC's SIG_VALTYPE_: 0 integer (the default), 1 IEEE float (binary32), 2 IEEE double (binary64).
  const std::string type = m.choice_or("value_type", "integer", {"integer", "float", "double"});
  s.value_type = type == "float"    ? can::ValueType::kFloat32
                 : type == "double" ? can::ValueType::kFloat64
                                    : can::ValueType::kInteger;
  if (s.value_type != can::ValueType::kInteger && m.has("signed")) {
    m.fail("signed", "a " + type + " signal is an IEEE 754 value, which carries its own sign: leave out `signed`");
  }
  s.is_signed = m.boolean_or("signed", false);
  s.scale = m.number_or("scale", 1.0, -1e12, 1e12);
  s.offset = m.number_or("offset", 0.0, -1e12, 1e12);
  if (m.has("no_reading"))
    s.no_reading_raw = m.integer("no_reading", std::numeric_limits<long>::min(), std::numeric_limits<long>::max());
  const std::string unit = m.text("unit");
  if (unit != can::field_unit(s.field)) {
    m.fail("unit", "'" + unit + "' for " + field + ", which is in " + std::string(can::field_unit(s.field)) +
                       " (scale the signal into it)");
  }
  m.finish();
  return s;
}

can::SignalMap read(YamlMap root) {
  can::SignalMap map;
  map.name = root.text("name");
  map.pole_pairs = static_cast<int>(root.integer_or("pole_pairs", 0, 0, 100));
  YamlMap sample = root.map("sample");
  map.trigger_id = static_cast<std::uint32_t>(sample.integer("trigger", 0, 0x1FFFFFFF));
  map.trigger_extended = sample.boolean_or("extended", false);
  map.averaged = sample.boolean_or("averaged", false);
  sample.finish();
  for (YamlMap f : root.maps("frames")) {
    can::FrameSpec spec;
    spec.extended = f.boolean_or("extended", false);
    spec.id = static_cast<std::uint32_t>(f.integer("id", 0, spec.extended ? 0x1FFFFFFF : 0x7FF));
    spec.length = static_cast<std::uint8_t>(f.integer_or("length", 8, 1, 64));
    for (YamlMap s : f.maps("signals")) spec.signals.push_back(read_signal(std::move(s)));
    f.finish();
    map.frames.push_back(std::move(spec));
  }
  root.finish();
  if (const std::string e = can::check_layout(map); !e.empty()) root.fail("frames", e);
  if (const std::string e = can::missing_quantities(map); !e.empty()) root.fail("frames", e);
  return map;
}

}  // namespace

can::SignalMap load_signal_map(const std::string& path) { return read(YamlMap::load_file(path)); }

can::SignalMap parse_signal_map(const std::string& text, const std::string& name) {
  return read(YamlMap::load_string(text, name));
}

}  // namespace rpem::io
