#include "rpem/supervisor/config.hpp"

#include <cmath>

#include "rpem/io/yaml_map.hpp"

namespace rpem::supervisor {
namespace {

PartLimits read_part(io::YamlMap m, double rated_current_A) {
  PartLimits p;
  p.warning_C = m.number("warning_C", -50.0, 400.0);
  p.limit_C = m.number("limit_C", -50.0, 400.0);
  if (!(p.limit_C > p.warning_C)) m.fail("limit_C", "must be above warning_C");
  p.floor_A = m.number("floor_A", 0.0, rated_current_A);
  p.raw_sd_K = m.number("raw_sd_K", 0.0, 100.0);
  p.max_rate_K_s = m.number("max_rate_K_s", 0.0, 100.0);
  m.finish();
  return p;
}

std::int64_t to_us(double s) { return std::llround(s * 1e6); }

}  // namespace

Config load_config(const std::string& path) {
  io::YamlMap root = io::YamlMap::load_file(path);
  io::YamlMap s = root.map("supervisor");
  root.finish();
  Config c;
  c.rated_current_A = s.number("rated_current_A", 1e-3, 1e5);
  c.magnet = read_part(s.map("magnet"), c.rated_current_A);
  c.winding = read_part(s.map("winding"), c.rated_current_A);
  io::YamlMap f = s.map("freshness");
  c.freshness.max_age_us = to_us(f.number("max_age_s", 1e-3, 3600.0));
  c.freshness.max_skew_us = to_us(f.number("max_skew_s", 0.0, 60.0));
  f.finish();
  s.finish();
  return c;
}

}  // namespace rpem::supervisor
