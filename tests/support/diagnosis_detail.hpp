#pragma once
// What a test case's detail line says about how a diagnosis fitted (docs/diagnose.md, "Outliers and the
// robust loss", "Calibrated despite a large mismatch"), so that a seed study shows where either happened.

#include <string>

#include "rpem/analysis/diagnose/diagnosis.hpp"

namespace rpem::test {

inline std::string fitting_detail(const analysis::Diagnosis& d) {
  std::string s;
  for (std::size_t i = 0; i < analysis::kCalibrated.size(); ++i) {
    if (d.calibration.identification[i] == analysis::Identification::kRejectsConfiguration) {
      s += std::string(" ") + analysis::kCalibrated[i] + " calibrated despite a large mismatch;";
    }
  }
  if (d.least_squares) s += " robust loss (outliers moved the least-squares fit);";
  return s;
}

}  // namespace rpem::test
