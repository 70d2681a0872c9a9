#pragma once
// Independent random streams from one seed: the machine draw, the scenario, the ADC noise, the link's timing
// and the start time each have their own, so that changing one setting does not reshuffle the others.
#include <cstdint>
#include <random>

namespace indep::vesc {

enum class Stream : std::uint64_t { machine = 11, scenario = 12, adc = 13, link = 14, clock = 15, offsets = 16 };

inline std::mt19937_64 stream_rng(std::uint64_t seed, Stream stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream)};
  return std::mt19937_64(seq);
}

}  // namespace indep::vesc
