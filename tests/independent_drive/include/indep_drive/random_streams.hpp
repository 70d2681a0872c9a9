#pragma once
// Independent random streams from one seed: the machine draw, the sensors, the averaging intervals and the
// effect parameters each have their own, so switching one on does not change the others' numbers.
#include <cstdint>
#include <random>

namespace indep {

enum class Stream : std::uint64_t { machine = 1, sensors = 2, effects = 3, intervals = 4, rotor = 5, averaged_noise = 6 };

inline std::mt19937_64 stream_rng(std::uint64_t seed, Stream stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream)};
  return std::mt19937_64(seq);
}

}  // namespace indep
