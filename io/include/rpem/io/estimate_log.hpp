#pragma once
// The estimate CSV written by `rpem estimate` (docs/drive-log.md, "Estimate CSV"): one row per
// estimator sample (or every N-th), SI units, with the diagnostics that explain each estimate.

#include <fstream>
#include <string>

#include "rpem/core/drive_estimator.hpp"

namespace rpem::io {

class EstimateLogWriter {
 public:
  explicit EstimateLogWriter(const std::string& path);
  void write(const core::Estimate& e, const core::DriveEstimator& estimator) { write(e, estimator.core()); }
  /// The same for any estimator built on RpemEstimator (the averaged one too).
  void write(const core::Estimate& e, const core::RpemEstimator& core);

 private:
  std::ofstream out_;
  std::string line_;
};

}  // namespace rpem::io
