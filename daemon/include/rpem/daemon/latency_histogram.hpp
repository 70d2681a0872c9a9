#pragma once
// Latency statistics without allocation: min, mean and max exactly, percentiles to the bin. Two bin schemes:
// LatencyHistogram, 1 µs bins up to 10 ms and an overflow bin (the loop's wake-up latency, cyclictest's format);
// WideLatencyHistogram, bins 1/64 of an octave wide from 1 µs to 2²⁷ µs (134 s), so a percentile is within 1.6 %
// of its value whether latencies are microseconds (a drive streaming at 8 kHz) or seconds (a VESC polled at 1 Hz,
// a Hall drive's counted windows held 0.25 s). Real-time safe.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace rpem::daemon {

/// 1 µs each up to 10 ms; the last bin holds everything beyond.
struct MicrosecondBins {
  static constexpr int kOverflow = 10'000;
  [[nodiscard]] static int of(double us) noexcept { return us >= kOverflow ? kOverflow : static_cast<int>(us); }
  [[nodiscard]] static double upper_edge(int bin) noexcept { return bin + 1.0; }
};

/// [0, 1) µs, then 64 bins per octave [2^k, 2^(k+1)) µs for k = 0…26 (each at most 1/64 of its lower edge wide),
/// then everything beyond.
struct OctaveBins {
  static constexpr int kPerOctave = 64, kOctaves = 27;
  static constexpr int kOverflow = 1 + kPerOctave * kOctaves;
  [[nodiscard]] static int of(double us) noexcept {
    if (!(us >= 1.0)) return 0;
    int exponent = 0;
    const double mantissa = std::frexp(us, &exponent);  // us = mantissa·2^exponent, mantissa ∈ [0.5, 1)
    const int octave = exponent - 1;
    if (octave >= kOctaves) return kOverflow;
    return 1 + octave * kPerOctave + static_cast<int>((2.0 * mantissa - 1.0) * kPerOctave);
  }
  [[nodiscard]] static double upper_edge(int bin) noexcept {
    if (bin == 0) return 1.0;
    const int octave = (bin - 1) / kPerOctave, step = (bin - 1) % kPerOctave;
    return std::ldexp(1.0 + (step + 1.0) / kPerOctave, octave);
  }
};

template <class Bins>
class Histogram {
 public:
  static constexpr int kBins = Bins::kOverflow;  ///< the overflow bin's index

  void add(double us) noexcept {
    const double v = std::max(0.0, us);
    ++counts_[static_cast<std::size_t>(Bins::of(v))];
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
  /// Count in bin `b` (MicrosecondBins: the 1-µs bin `b`; kBins: everything beyond the range).
  [[nodiscard]] std::int64_t bin(int b) const noexcept { return counts_[static_cast<std::size_t>(std::clamp(b, 0, kBins))]; }
  /// The upper edge of the bin holding the q-quantile (q in (0, 1]), at most the max; the max if it overflowed.
  [[nodiscard]] double percentile(double q) const noexcept {
    if (n_ == 0) return 0.0;
    const auto target = static_cast<std::int64_t>(std::floor(q * static_cast<double>(n_) + 0.5));  // ≥ 0: half up
    std::int64_t seen = 0;
    for (int b = 0; b <= kBins; ++b) {
      seen += counts_[static_cast<std::size_t>(b)];
      if (seen >= std::max<std::int64_t>(1, target)) return b == kBins ? max_ : std::min(max_, Bins::upper_edge(b));
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

using LatencyHistogram = Histogram<MicrosecondBins>;
using WideLatencyHistogram = Histogram<OctaveBins>;

}  // namespace rpem::daemon
