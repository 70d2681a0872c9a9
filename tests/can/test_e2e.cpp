#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "rpem/can/e2e.hpp"
#include "support/seed.hpp"

namespace rpem::can {
namespace {

TEST(Crc16, CcittFalseCheckValue) {
  const char* s = "123456789";  // the catalogue check value of CRC-16/CCITT-FALSE
  EXPECT_EQ(crc16_ccitt_false(reinterpret_cast<const std::uint8_t*>(s), std::strlen(s)), 0x29B1);
}

TEST(E2e, DetectsEverySingleBitErrorAndTheWrongDataId) {
  std::mt19937_64 rng(test::test_seed(3));
  CanFrame f;
  f.len = 64;
  f.fd = true;
  for (std::size_t k = 3; k < 64; ++k) f.data[k] = static_cast<std::uint8_t>(rng());
  e2e_protect(f, 0x5100, 42);
  ASSERT_TRUE(e2e_check(f, 0x5100));
  EXPECT_EQ(e2e_counter(f), 42);
  EXPECT_FALSE(e2e_check(f, 0x5101));
  for (int byte = 0; byte < 64; ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      CanFrame g = f;
      g.data[static_cast<std::size_t>(byte)] ^= static_cast<std::uint8_t>(1U << bit);
      EXPECT_FALSE(e2e_check(g, 0x5100)) << byte << ":" << bit;
    }
  }
}

}  // namespace
}  // namespace rpem::can
