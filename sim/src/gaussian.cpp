#include "rpem/sim/gaussian.hpp"

#include <cmath>

namespace rpem::sim {
namespace {

constexpr int kLayers = 128;
constexpr double kR = 3.442619855899;          // start of the tail
constexpr double kArea = 9.91256303526217e-3;  // area of each layer

struct Tables {
  std::array<double, kLayers + 1> x{};  // layer edges, x[0] = v/f(r), x[1] = r, …, x[128] = 0
  std::array<double, kLayers + 1> f{};  // f(x) = exp(−x²/2)
  Tables() {
    x[0] = kArea / std::exp(-0.5 * kR * kR);
    x[1] = kR;
    for (int i = 2; i < kLayers; ++i) {
      x[i] = std::sqrt(-2.0 * std::log(kArea / x[i - 1] + std::exp(-0.5 * x[i - 1] * x[i - 1])));
    }
    x[kLayers] = 0.0;
    for (int i = 0; i <= kLayers; ++i) f[i] = std::exp(-0.5 * x[i] * x[i]);
  }
};

// Built once at start-up, so the per-sample path reads it without a guard.
const Tables kTables;
const Tables& tables() { return kTables; }

std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }

}  // namespace

GaussianNoise::GaussianNoise(std::uint64_t seed) noexcept {
  // splitmix64 expands the seed into the xoshiro state.
  for (auto& word : s_) {
    seed += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = seed;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    word = z ^ (z >> 31);
  }
  (void)tables();
}

std::uint64_t GaussianNoise::next() noexcept {
  const std::uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double GaussianNoise::tail(bool negative) noexcept {
  double x = 0.0, y = 0.0;
  do {
    x = -std::log(1.0 - uniform()) / kR;
    y = -std::log(1.0 - uniform());
  } while (2.0 * y < x * x);
  return negative ? -(kR + x) : kR + x;
}

double GaussianNoise::operator()() noexcept {
  const Tables& t = tables();
  while (true) {
    const std::uint64_t bits = next();
    const int i = static_cast<int>(bits & (kLayers - 1));
    const bool negative = (bits >> 7) & 1U;
    const double u = static_cast<double>(bits >> 11) * 0x1.0p-53;  // [0, 1)
    const double x = u * t.x[static_cast<std::size_t>(i)];
    if (x < t.x[static_cast<std::size_t>(i) + 1]) return negative ? -x : x;  // inside the layer's core
    if (i == 0) return tail(negative);
    // Wedge: accept with the density's shape between the layer's edges.
    const double y = t.f[static_cast<std::size_t>(i)] +
                     uniform() * (t.f[static_cast<std::size_t>(i) + 1] - t.f[static_cast<std::size_t>(i)]);
    if (y < std::exp(-0.5 * x * x)) return negative ? -x : x;
  }
}

}  // namespace rpem::sim
