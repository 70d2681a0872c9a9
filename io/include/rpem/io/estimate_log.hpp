#pragma once
// The estimate CSV written by `rpem estimate` (docs/drive-log.md, "Estimate CSV"): one row per
// estimator sample (or every N-th), SI units, with the diagnostics that explain each estimate; with
// `--thermal`, the fused temperatures of every node beside the ones the estimates alone imply.

#include <fstream>
#include <string>
#include <vector>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/thermal_fusion.hpp"

namespace rpem::io {

class EstimateLogWriter {
 public:
  /// `thermal_nodes`: the names of the thermal network's nodes (their columns follow the estimator's);
  /// empty: no thermal columns.
  explicit EstimateLogWriter(const std::string& path, const std::vector<std::string>& thermal_nodes = {});
  void write(const core::Estimate& e, const core::DriveEstimator& estimator,
             const core::ThermalEstimate* thermal = nullptr) {
    write(e, estimator.core(), thermal);
  }
  /// The same for any estimator built on RpemEstimator (the averaged one too).
  void write(const core::Estimate& e, const core::RpemEstimator& core, const core::ThermalEstimate* thermal = nullptr);

 private:
  std::ofstream out_;
  std::string line_;
  std::size_t thermal_nodes_ = 0;
};

}  // namespace rpem::io
