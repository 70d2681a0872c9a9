#pragma once
// Wake-up latency statistics without allocation: 1 µs bins up to 10 ms and an overflow bin; min, mean,
// max exactly, percentiles to the bin. Real-time safe.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace rpem::daemon {

class LatencyHistogram {
 public:
  static constexpr int kBins = 10'000;  ///< 1 µs each

  void add(double us) noexcept {
    const double v = std::max(0.0, us);
    const auto bin = v >= kBins ? kBins : static_cast<int>(v);
    ++counts_[static_cast<std::size_t>(bin)];
    ++n_;
    sum_ += v;
    min_ = std::min(min_, v);
    max_ = std::max(max_, v);
  }
  void reset() noexcept {
    counts_.fill(0);
    n_ = 0;
    sum_ = 0.0;
    min_ = std::numeric_limits<double>::infinity();
    max_ = 0.0;
  }
  [[nodiscard]] std::int64_t count() const noexcept { return n_; }
  [[nodiscard]] double min() const noexcept { return n_ ? min_ : 0.0; }
  [[nodiscard]] double max() const noexcept { return max_; }
  [[nodiscard]] double mean() const noexcept { return n_ ? sum_ / static_cast<double>(n_) : 0.0; }
  /// Count in 1-µs bin `us` (the last bin holds everything beyond the range).
  [[nodiscard]] std::int64_t bin(int us) const noexcept {
    return counts_[static_cast<std::size_t>(std::clamp(us, 0, kBins))];
  }
  /// The upper edge of the bin holding the q-quantile (q in (0, 1]); the max if in the overflow bin.
  [[nodiscard]] double percentile(double q) const noexcept {
    if (n_ == 0) return 0.0;
    const auto target = static_cast<std::int64_t>(std::floor(q * static_cast<double>(n_) + 0.5));  // ≥ 0: half up
    std::int64_t seen = 0;
    for (int b = 0; b <= kBins; ++b) {
      seen += counts_[static_cast<std::size_t>(b)];
      if (seen >= std::max<std::int64_t>(1, target)) return b == kBins ? max_ : std::min(max_, b + 1.0);
    }
    return max_;
  }

 private:
  std::array<std::int64_t, kBins + 1> counts_{};
  std::int64_t n_ = 0;
  double sum_ = 0.0;
  double min_ = std::numeric_limits<double>::infinity();
  double max_ = 0.0;
};

}  // namespace rpem::daemon
