#pragma once
// Seeded random streams, one per purpose (parameter draw, profile, measurement noise), so that changing one
// (say, the profile) leaves the others' numbers unchanged. Uniform and normal variates are made here from the
// raw 64-bit output (not with <random>'s distributions, whose algorithms the standard leaves to the library):
// a seed gives the same numbers with any standard library.
#include <cmath>
#include <cstdint>
#include <random>

namespace indep_thermal {

enum class Stream : std::uint32_t { parameters = 11, electrical = 12, profile = 13, noise = 14 };

class Rng {
 public:
  Rng(std::uint64_t seed, Stream stream) {
    std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                      static_cast<std::uint32_t>(stream)};
    engine_.seed(seq);
  }

  /// Uniform in [0, 1): the top 53 bits of one draw.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Log-uniform in [lo, hi], lo > 0: a factor that is as likely halved as doubled.
  double log_uniform(double lo, double hi) { return lo * std::exp(std::log(hi / lo) * uniform()); }
  /// Standard normal by Box-Muller (both variates used).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * kPi * u2);
  }

  static constexpr double kPi = 3.14159265358979323846;

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace indep_thermal
