// The loop holds only SampleEstimators (core/sample_estimator.hpp), the k-th for a SourceSample's k-th
// alternative: an estimator whose step may throw — not real-time safe — is refused.
#include "rpem/daemon/loop_estimator.hpp"

namespace {

/// DriveEstimator, but stepping a sample may throw.
struct ThrowingEstimator : rpem::core::DriveEstimator {
  using DriveEstimator::DriveEstimator;
  rpem::core::Estimate step(const Sample& s) { return DriveEstimator::step(s); }
};

}  // namespace

#ifdef RPEM_COMPILE_FAIL
using Estimators = rpem::daemon::OneOfEstimators<ThrowingEstimator, rpem::core::AveragedDriveEstimator>;
#else
using Estimators = rpem::daemon::OneOfEstimators<rpem::core::DriveEstimator, rpem::core::AveragedDriveEstimator>;
#endif

int main() { return static_cast<int>(std::variant_size_v<Estimators>) - 2; }
