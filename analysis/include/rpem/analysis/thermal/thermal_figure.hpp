#pragma once
// The fused temperatures against measured ones (docs/thermal.md, "Figures"): per node (magnet, winding) the
// fused estimate of `rpem estimate --thermal` with its ±2σ band, what the estimator alone says (the inverse
// law of ψ̂m or r̂s, held where it does not adapt) and the measured temperature — `rpem figures --thermal-estimate`.

#include <string>

namespace rpem::analysis {

struct ThermalFigureInput {
  std::string estimate_csv;  ///< `rpem estimate --thermal`'s CSV
  std::string measured_csv;  ///< a CSV with a time column `t` [s] and the measured temperatures [°C]; empty: none
  std::string magnet_column = "T_magnet";
  std::string winding_column = "T_winding";
  double judged_after_s = 0.0;  ///< a vertical line where a held-out part begins; 0: none
};

/// Writes `png_path` (and its .gp script); returns the share of measured points inside the ±2σ band per node
/// (magnet, winding), interpolating the fused estimate at the measured times (NaN where none was measured).
struct ThermalFigureCoverage {
  double magnet = 0.0, winding = 0.0;
};
ThermalFigureCoverage write_thermal_figure(const std::string& png_path, const ThermalFigureInput& in);

}  // namespace rpem::analysis
