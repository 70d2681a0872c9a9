#pragma once
// Seeds for property tests: RPEM_SEED overrides the default; every test prints the seed it used so a
// failure can be replayed with RPEM_SEED=<seed>.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <string>

namespace rpem::test {

inline std::uint64_t test_seed(std::uint64_t fallback) {
  const char* env = std::getenv("RPEM_SEED");
  const std::uint64_t seed = env ? std::strtoull(env, nullptr, 10) : fallback;
  ::testing::Test::RecordProperty("seed", std::to_string(seed));
  std::printf("[ seed     ] %llu (replay with RPEM_SEED=%llu)\n", static_cast<unsigned long long>(seed),
              static_cast<unsigned long long>(seed));
  return seed;
}

}  // namespace rpem::test
