#pragma once
// What the generator's tests share: the outrunner of the repository's configuration, and short scenarios.
#include <string>
#include <vector>

#include "indep_vesc/case.hpp"
#include "indep_vesc/generator.hpp"

namespace indep::vesc::testing {

inline std::string source_path(const std::string& relative) { return std::string(RPEM_TEST_SOURCE_DIR) + "/" + relative; }

/// The 6374 outrunner, its true machine off by fixed amounts, temperatures constant.
inline Case outrunner_case(double duration_s) {
  Case c;
  c.machine = read_machine_config(source_path("config/vesc-6374-outrunner.yaml"));
  c.duration_s = duration_s;
  c.draw.psi_m_rel = 0.15;
  c.draw.r_s_rel = -0.2;
  c.thermal.on = false;
  return c;
}

inline Segment segment(SegmentKind kind, double duration_s, double current_A = 0.0) {
  Segment s;
  s.kind = kind;
  s.duration_s = duration_s;
  s.current_A = current_A;
  return s;
}

/// The rows whose read falls in [t0, t1).
inline std::vector<const LogRow*> rows_between(const Result& r, double t0, double t1) {
  std::vector<const LogRow*> out;
  for (const LogRow& row : r.rows) {
    if (row.truth.t_read_s >= t0 && row.truth.t_read_s < t1) out.push_back(&row);
  }
  return out;
}

}  // namespace indep::vesc::testing
